#include "pre_import_checks.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <vector>

#include "clumpkit/core/error.hpp"

namespace clumpkit::detail {

namespace fs = std::filesystem;

namespace {

std::string lower_extension(const fs::path& path) {
  std::string ext = path.extension().string();
  for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return ext;
}

void trim(std::string& l) {
  while (!l.empty() && (l.back() == '\r' || l.back() == ' ' || l.back() == '\t')) l.pop_back();
  const size_t b = l.find_first_not_of(" \t");
  l = b == std::string::npos ? std::string() : l.substr(b);
}

struct PlyType {
  int bytes;
  bool integer;
  bool is_signed;
};

// PLY's scalar types with their sizes; nullptr for an unknown name.
const PlyType* ply_type(const std::string& name) {
  static const std::map<std::string, PlyType> types = {
      {"char", {1, true, true}},     {"uchar", {1, true, false}},   {"int8", {1, true, true}},
      {"uint8", {1, true, false}},   {"short", {2, true, true}},    {"ushort", {2, true, false}},
      {"int16", {2, true, true}},    {"uint16", {2, true, false}},  {"int", {4, true, true}},
      {"uint", {4, true, false}},    {"int32", {4, true, true}},    {"uint32", {4, true, false}},
      {"float", {4, false, true}},   {"float32", {4, false, true}}, {"double", {8, false, true}},
      {"float64", {8, false, true}}};
  const auto it = types.find(name);
  return it == types.end() ? nullptr : &it->second;
}

struct PlyProperty {
  bool list = false;
  PlyType count{};  // list only
  PlyType value{};
};

struct PlyElement {
  std::string name;
  long long count = 0;
  std::vector<PlyProperty> properties;
};

enum class PlyFormat { Ascii, BinaryLittle, BinaryBig };

// Largest value a list count of this (integer) type can hold.
long long max_count(const PlyType& t) {
  const int bits = 8 * t.bytes - (t.is_signed ? 1 : 0);
  return static_cast<long long>((1ULL << bits) - 1ULL);
}

// The ASCII body: one element instance per non-empty line, every token a number, every list
// count an integer within its type's range followed by at least that many numbers.
void check_ply_ascii_body(std::istream& in, int line_no, const std::vector<PlyElement>& elements,
                          const std::string& where) {
  std::string line;
  std::vector<std::string> tokens;
  for (const PlyElement& e : elements) {
    for (long long i = 0; i < e.count; ++i) {
      bool got = false;
      while (std::getline(in, line)) {
        ++line_no;
        if (line.find_first_not_of(" \t\r") != std::string::npos) {
          got = true;
          break;
        }
      }
      if (!got)
        throw InputError(where, "line " + std::to_string(line_no),
                         "malformed PLY body: " + std::to_string(i) + " of the " +
                             std::to_string(e.count) + " '" + e.name +
                             "' elements the header announces");
      std::istringstream words(line);
      tokens.assign(std::istream_iterator<std::string>(words), std::istream_iterator<std::string>());
      const auto bad = [&](const std::string& what) {
        throw InputError(where, "line " + std::to_string(line_no),
                         "malformed PLY body ('" + e.name + "' element): " + what);
      };
      const auto number = [&](std::size_t k) {
        if (k >= tokens.size()) bad("fewer values than its properties need");
        const char* s = tokens[k].c_str();
        char* end = nullptr;
        const double v = std::strtod(s, &end);
        if (end == s || *end != '\0') bad("'" + tokens[k] + "' is not a number");
        return v;
      };
      std::size_t k = 0;
      for (const PlyProperty& p : e.properties) {
        if (!p.list) {
          number(k++);
          continue;
        }
        const double c = number(k++);
        if (!(c >= 0) || c != std::floor(c) || c > static_cast<double>(max_count(p.count)))
          bad("list count '" + tokens[k - 1] + "' is not an integer its type can hold");
        if (c > static_cast<double>(tokens.size() - k))
          bad("a list announces " + tokens[k - 1] + " values, the line has " +
              std::to_string(tokens.size() - k));
        const auto n = static_cast<std::size_t>(c);
        for (std::size_t j = 0; j < n; ++j) number(k + j);
        k += n;
      }
    }
  }
}

// The binary body: every element instance present, list counts non-negative and within the
// bytes that follow.
void check_ply_binary_body(std::istream& in, bool big_endian,
                           const std::vector<PlyElement>& elements, const std::string& where) {
  const std::vector<char> body((std::istreambuf_iterator<char>(in)),
                               std::istreambuf_iterator<char>());
  std::size_t at = 0;
  const bool host_little = [] {
    const std::uint16_t one = 1;
    unsigned char b = 0;
    std::memcpy(&b, &one, 1);
    return b == 1;
  }();
  for (const PlyElement& e : elements) {
    for (long long i = 0; i < e.count; ++i) {
      const auto bad = [&](const std::string& what) {
        throw InputError(where, "byte " + std::to_string(at) + " of the body",
                         "malformed binary PLY ('" + e.name + "' element " + std::to_string(i) +
                             " of " + std::to_string(e.count) + "): " + what);
      };
      for (const PlyProperty& p : e.properties) {
        if (!p.list) {
          if (body.size() - at < static_cast<std::size_t>(p.value.bytes))
            bad("the file ends before the elements the header announces");
          at += static_cast<std::size_t>(p.value.bytes);
          continue;
        }
        const auto n = static_cast<std::size_t>(p.count.bytes);
        if (body.size() - at < n) bad("the file ends before the elements the header announces");
        unsigned char raw[4] = {0, 0, 0, 0};
        for (std::size_t j = 0; j < n; ++j)
          raw[j] = static_cast<unsigned char>(body[at + (big_endian == host_little ? n - 1 - j : j)]);
        std::uint64_t u = 0;  // raw now holds the count in host (little-endian) order
        for (std::size_t j = n; j-- > 0;) u = (u << 8) | raw[j];
        long long c = static_cast<long long>(u);
        if (p.count.is_signed && (u >> (8 * n - 1)) != 0) c -= static_cast<long long>(1ULL << (8 * n));
        at += n;
        if (c < 0) bad("negative list count " + std::to_string(c));
        const std::size_t need = static_cast<std::size_t>(c) * static_cast<std::size_t>(p.value.bytes);
        if (body.size() - at < need)
          bad("a list announces " + std::to_string(c) + " values, the file has " +
              std::to_string((body.size() - at) / static_cast<std::size_t>(p.value.bytes)) +
              " left");
        at += need;
      }
    }
  }
}

}  // namespace

// assimp 5.2 loops forever on a PLY header that never reaches "end_header" (found by fuzzing: a
// corrupted property line), abort()s on unknown property types, and reserves memory by the
// counts it reads (element counts in the header, list counts in the body: an ASCII face line
// "3429496729 5 1" asked for 34 GB). assimp picks its PLY reader by extension or by a leading
// "ply", so both are checked.
void check_ply(const fs::path& path, const std::string& where) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  if (!std::getline(in, line)) return;
  trim(line);
  if (line.rfind("ply", 0) != 0 && lower_extension(path) != ".ply") return;
  if (line != "ply") throw InputError(where, "", "not a PLY file (the first line must be 'ply')");
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  std::vector<PlyElement> elements;
  bool have_format = false;
  PlyFormat format = PlyFormat::Ascii;
  int n = 1;
  for (;;) {
    if (!std::getline(in, line)) throw InputError(where, "", "PLY header without end_header");
    ++n;
    trim(line);
    const auto bad = [&](const std::string& what) {
      throw InputError(where, "line " + std::to_string(n), "malformed PLY header (" + what + ")");
    };
    if (line == "end_header") break;
    std::istringstream words(line);
    std::string word;
    words >> word;
    if (word == "comment" || word == "obj_info") continue;
    if (word == "format") {
      std::string f;
      words >> f;
      if (f == "ascii") format = PlyFormat::Ascii;
      else if (f == "binary_little_endian") format = PlyFormat::BinaryLittle;
      else if (f == "binary_big_endian") format = PlyFormat::BinaryBig;
      else bad("unknown format '" + f + "'");
      have_format = true;
    } else if (word == "element") {
      PlyElement e;
      e.count = -1;
      words >> e.name >> e.count;
      // Every element takes at least one byte of the file (a huge count made assimp allocate
      // tens of GB).
      if (e.count < 0 || ec || static_cast<unsigned long long>(e.count) > size)
        bad("element count missing or larger than the file");
      elements.push_back(e);
    } else if (word == "property") {
      if (elements.empty()) bad("a property before any element");
      std::string t1, t2, t3;
      words >> t1 >> t2 >> t3;
      PlyProperty p;
      if (t1 == "list") {
        const PlyType* count = ply_type(t2);
        const PlyType* value = ply_type(t3);
        if (!count || !value) bad("unknown property type");
        if (!count->integer) bad("a list count must have an integer type");
        p.list = true;
        p.count = *count;
        p.value = *value;
      } else {
        const PlyType* value = ply_type(t1);
        if (!value) bad("unknown property type");  // assimp abort()ed later (fuzzing)
        p.value = *value;
      }
      elements.back().properties.push_back(p);
    } else {
      bad("expected format, element, property, comment or end_header");
    }
  }
  if (!have_format) throw InputError(where, "", "malformed PLY header (no format line)");
  if (format == PlyFormat::Ascii)
    check_ply_ascii_body(in, n, elements, where);
  else
    check_ply_binary_body(in, format == PlyFormat::BinaryBig, elements, where);
}

// assimp 5.2 crashes (SEGV) on OFF files whose face lines are not what the counts promise (found
// by fuzzing). OFF is simple enough to check completely: the header, the counts, nv vertex lines
// of 3 numbers and nf face lines "k i1 ... ik" (k >= 3, indices < nv; colours may follow).
void check_off(const fs::path& path, const std::string& where) {
  if (lower_extension(path) != ".off") return;
  std::ifstream in(path, std::ios::binary);
  std::string line;
  int n = 0;
  auto next = [&]() {  // the next line that is neither empty nor a comment
    while (std::getline(in, line)) {
      ++n;
      const size_t b = line.find_first_not_of(" \t\r");
      if (b != std::string::npos && line[b] != '#') return true;
    }
    return false;
  };
  auto bad = [&](const std::string& what) {
    throw InputError(where, "line " + std::to_string(n), "malformed OFF file: " + what);
  };
  if (!next()) bad("empty");
  std::istringstream head(line);
  std::string magic;
  head >> magic;
  if (magic.size() < 3 || magic.compare(magic.size() - 3, 3, "OFF") != 0) bad("no OFF header");
  long long nv = -1, nf = -1, ne = -1;
  if (!(head >> nv)) {  // counts on their own line
    if (!next()) bad("missing counts");
    std::istringstream counts(line);
    counts >> nv >> nf >> ne;
  } else {
    head >> nf >> ne;
  }
  if (nv < 0 || nf < 0 || nv > 100'000'000 || nf > 100'000'000) bad("bad vertex/face counts");
  for (long long v = 0; v < nv; ++v) {
    if (!next()) bad("fewer vertices than announced");
    std::istringstream xyz(line);
    double x, y, z;
    if (!(xyz >> x >> y >> z)) bad("a vertex needs 3 numbers");
  }
  for (long long f = 0; f < nf; ++f) {
    if (!next()) bad("fewer faces than announced");
    std::istringstream face(line);
    long long k = 0;
    if (!(face >> k) || k < 1 || k > 1'000'000) bad("a face starts with its vertex count");
    for (long long j = 0; j < k; ++j) {
      long long i = -1;
      if (!(face >> i) || i < 0 || i >= nv) bad("face index missing or out of range");
    }
  }
}


}  // namespace clumpkit::detail
