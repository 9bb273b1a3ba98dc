// PLY (Turk 1994; the format of Stanford's scans and of most scanners' exports), read completely
// here: see mesh_readers.hpp for why not by assimp.
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <string_view>
#include <vector>

#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"
#include "mesh_readers.hpp"

namespace clumpkit::detail {

namespace fs = std::filesystem;

namespace {

struct PlyType {
  int bytes;
  bool integer;
  bool is_signed;
};

// PLY's scalar types with their sizes; nullptr for an unknown name.
const PlyType* ply_type(std::string_view name) {
  static const std::map<std::string, PlyType, std::less<>> types = {
      {"char", {1, true, true}},    {"uchar", {1, true, false}},   {"int8", {1, true, true}},
      {"uint8", {1, true, false}},  {"short", {2, true, true}},    {"ushort", {2, true, false}},
      {"int16", {2, true, true}},   {"uint16", {2, true, false}},  {"int", {4, true, true}},
      {"uint", {4, true, false}},   {"int32", {4, true, true}},    {"uint32", {4, true, false}},
      {"float", {4, false, true}},  {"float32", {4, false, true}}, {"double", {8, false, true}},
      {"float64", {8, false, true}}};
  const auto it = types.find(name);
  return it == types.end() ? nullptr : &it->second;
}

// Largest value a list count of this (integer) type can hold.
long long max_count(const PlyType& t) {
  const int bits = 8 * t.bytes - (t.is_signed ? 1 : 0);
  return static_cast<long long>((1ULL << bits) - 1ULL);
}

// What the reader does with a property's values.
enum class Role { Skip, X, Y, Z, FaceIndices, StripIndices };

struct PlyProperty {
  std::string name;
  bool list = false;
  PlyType count{};  // list only
  PlyType value{};
  Role role = Role::Skip;
};

struct PlyElement {
  std::string name;
  long long count = 0;
  int line = 0;  // of its header line
  std::vector<PlyProperty> properties;
};

enum class PlyFormat { Ascii, BinaryLittle, BinaryBig };

struct Header {
  PlyFormat format = PlyFormat::Ascii;
  std::vector<PlyElement> elements;
  std::size_t body = 0;  // offset of the first body byte
  int lines = 0;         // header lines, "ply" and "end_header" included
};

Header read_header(const std::string& text, const std::string& where) {
  Header h;
  TextLines lines(text, false);
  std::vector<std::string_view> w;
  const auto bad = [&](const std::string& what) {
    throw InputError(where, "line " + std::to_string(lines.line()),
                     "malformed PLY header (" + what + ")");
  };
  if (!lines.next(w) || lines.line() != 1 || w.size() != 1 || w[0] != "ply")
    throw InputError(where, "line 1", "not a PLY file (the first line must be 'ply')");
  bool have_format = false;
  for (;;) {
    if (!lines.next(w)) throw InputError(where, "", "PLY header without end_header");
    if (w[0] == "end_header") {
      if (w.size() != 1) bad("text after end_header");
      break;
    }
    if (w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "format") {
      if (have_format) bad("a second format line");
      if (!h.elements.empty()) bad("the format line must come before the elements");
      if (w.size() < 2 || w.size() > 3) bad("expected 'format ascii|binary_little_endian|...'");
      if (w[1] == "ascii")
        h.format = PlyFormat::Ascii;
      else if (w[1] == "binary_little_endian")
        h.format = PlyFormat::BinaryLittle;
      else if (w[1] == "binary_big_endian")
        h.format = PlyFormat::BinaryBig;
      else
        bad("unknown format " + shown(w[1]));
      have_format = true;
    } else if (w[0] == "element") {
      if (w.size() != 3) bad("expected 'element NAME COUNT'");
      PlyElement e;
      e.name = std::string(w[1]);
      e.line = lines.line();
      // Every instance takes at least one byte of the file: a bound on the loops below (binary
      // elements without properties take none, but then count no more than the file's bytes).
      if (!whole_integer(w[2], e.count) || e.count < 0 ||
          static_cast<unsigned long long>(e.count) > text.size())
        bad("element count " + shown(w[2]) + " is not a whole number the file can hold");
      for (const PlyElement& o : h.elements)
        if (o.name == e.name) bad("a second " + shown(e.name) + " element");
      h.elements.push_back(e);
    } else if (w[0] == "property") {
      if (h.elements.empty()) bad("a property before any element");
      PlyProperty p;
      if (w.size() >= 2 && w[1] == "list") {
        if (w.size() != 5) bad("expected 'property list COUNT_TYPE VALUE_TYPE NAME'");
        const PlyType* count = ply_type(w[2]);
        const PlyType* value = ply_type(w[3]);
        if (!count || !value) bad("unknown property type");
        if (!count->integer) bad("a list count must have an integer type");
        p.list = true;
        p.count = *count;
        p.value = *value;
        p.name = std::string(w[4]);
      } else {
        if (w.size() != 3) bad("expected 'property TYPE NAME'");
        const PlyType* value = ply_type(w[1]);
        if (!value) bad("unknown property type " + shown(w[1]));
        p.value = *value;
        p.name = std::string(w[2]);
      }
      for (const PlyProperty& o : h.elements.back().properties)
        if (o.name == p.name) bad("a second property " + shown(p.name));
      h.elements.back().properties.push_back(p);
    } else {
      bad("expected format, element, property, comment or end_header, not " + shown(w[0]));
    }
  }
  if (!have_format) throw InputError(where, "", "malformed PLY header (no format line)");
  h.body = lines.offset();
  h.lines = lines.line();
  return h;
}

// Gives the reader's roles to the properties it reads; checks what the reader needs is there.
long long assign_roles(Header& h, const std::string& where) {
  long long vertices = -1;
  for (PlyElement& e : h.elements) {
    const auto bad = [&](const std::string& what) {
      throw InputError(where, "line " + std::to_string(e.line),
                       "PLY " + shown(e.name) + " " + what);
    };
    if (e.name == "vertex") {
      int found = 0;
      for (PlyProperty& p : e.properties) {
        const Role r = p.name == "x"   ? Role::X
                       : p.name == "y" ? Role::Y
                       : p.name == "z" ? Role::Z
                                       : Role::Skip;
        if (r == Role::Skip) continue;
        if (p.list) bad("element: its " + shown(p.name) + " property is a list");
        p.role = r;
        ++found;
      }
      if (found != 3) bad("element without x, y and z properties");
      if (e.count > INT_MAX) bad("element: more vertices than clumpkit can index");
      vertices = e.count;
    } else if (e.name == "face" || e.name == "tristrips") {
      PlyProperty* list = nullptr;
      for (PlyProperty& p : e.properties)
        if (p.name == "vertex_indices" || p.name == "vertex_index") list = &p;
      if (!list || !list->list) bad("element without a vertex_indices list");
      if (!list->value.integer) bad("element: vertex indices must have an integer type");
      list->role = e.name == "face" ? Role::FaceIndices : Role::StripIndices;
    }
  }
  if (vertices < 0) throw InputError(where, "", "PLY file without a 'vertex' element");
  return vertices;
}

// Collects vertices and turns index lists into triangles, checking every index.
class Builder {
 public:
  Builder(long long vertices, TriangleMesh& mesh) : nv_(vertices), mesh_(mesh) {}

  void coordinate(Role r, double v) { xyz_[static_cast<int>(r) - static_cast<int>(Role::X)] = v; }
  void end_vertex() { mesh_.vertices.emplace_back(xyz_[0], xyz_[1], xyz_[2]); }

  // An index list of a face (a polygon, fanned) or a strip; `fail` reports a bad index.
  template <class Fail>
  void indices(Role r, const std::vector<long long>& ix, const Fail& fail) {
    for (const long long i : ix)
      if ((i < 0 || i >= nv_) && !(r == Role::StripIndices && i == -1))
        fail("vertex index " + std::to_string(i) + " names no vertex (the file has " +
             std::to_string(nv_) + ")");
    if (r == Role::FaceIndices) {
      for (std::size_t k = 1; k + 1 < ix.size(); ++k)  // polygons of < 3 vertices bound nothing
        tri(ix[0], ix[k], ix[k + 1]);
      return;
    }
    std::size_t start = 0;  // a strip: (a b c), (c b d), (c d e), ... restarting after each -1
    for (std::size_t k = 0; k < ix.size(); ++k) {
      if (ix[k] == -1) {
        start = k + 1;
        continue;
      }
      if (k < start + 2) continue;
      if ((k - start) % 2 == 0)
        tri(ix[k - 2], ix[k - 1], ix[k]);
      else
        tri(ix[k - 1], ix[k - 2], ix[k]);
    }
  }

 private:
  void tri(long long a, long long b, long long c) {
    mesh_.triangles.emplace_back(static_cast<int>(a), static_cast<int>(b), static_cast<int>(c));
  }
  long long nv_;
  TriangleMesh& mesh_;
  double xyz_[3] = {0, 0, 0};
};

// The ASCII body: one element instance per non-empty line, every token a number, every list
// count an integer within its type's range followed by at least that many numbers.
void read_ascii_body(const std::string& text, const Header& h, Builder& out,
                     const std::string& where) {
  TextLines lines(text, false, h.body, h.lines);  // numbered on from the header's
  std::vector<std::string_view> tokens;
  std::vector<long long> ix;
  for (const PlyElement& e : h.elements) {
    const bool vertex = e.name == "vertex";
    for (long long i = 0; i < e.count; ++i) {
      lines.next(tokens);
      if (tokens.empty())
        throw InputError(where, "line " + std::to_string(lines.line()),
                         "malformed PLY body: " + std::to_string(i) + " of the " +
                             std::to_string(e.count) + " " + shown(e.name) +
                             " elements the header announces");
      const auto bad = [&](const std::string& what) {
        throw InputError(where, "line " + std::to_string(lines.line()),
                         "malformed PLY body (" + shown(e.name) + " element): " + what);
      };
      const auto number = [&](std::size_t k) {
        if (k >= tokens.size()) bad("fewer values than its properties need");
        double v = 0.0;
        if (!whole_number(tokens[k], v)) bad(shown(tokens[k]) + " is not a number");
        return v;
      };
      std::size_t k = 0;
      for (const PlyProperty& p : e.properties) {
        if (!p.list) {
          const double v = number(k++);
          if (p.role != Role::Skip) out.coordinate(p.role, v);
          continue;
        }
        const double c = number(k++);
        const std::string count(tokens[k - 1]);
        if (!(c >= 0) || c != std::floor(c) || c > static_cast<double>(max_count(p.count)))
          bad("list count " + shown(count) + " is not an integer its type can hold");
        if (c > static_cast<double>(tokens.size() - k))
          bad("a list announces " + count + " values, the line has " +
              std::to_string(tokens.size() - k));
        const auto n = static_cast<std::size_t>(c);
        ix.clear();
        for (std::size_t j = 0; j < n; ++j) {
          const double v = number(k + j);
          if (p.role == Role::Skip) continue;
          if (v != std::floor(v) || std::abs(v) > 9e15)
            bad("vertex index " + shown(tokens[k + j]) + " is not an integer");
          ix.push_back(static_cast<long long>(v));
        }
        k += n;
        if (p.role != Role::Skip) out.indices(p.role, ix, bad);
      }
      if (vertex) out.end_vertex();
    }
  }
}

// The binary body: every element instance present, list counts non-negative and within the
// bytes that follow.
void read_binary_body(const std::string& text, const Header& h, Builder& out,
                      const std::string& where) {
  const bool swap = [&] {
    const std::uint16_t one = 1;
    unsigned char b = 0;
    std::memcpy(&b, &one, 1);
    const bool host_little = b == 1;
    return host_little != (h.format == PlyFormat::BinaryLittle);
  }();
  std::size_t at = h.body;
  const std::size_t size = text.size();
  std::vector<long long> ix;
  // One value of type t at `at`, as a double (integers of up to 32 bits are exact).
  const auto value = [&](const PlyType& t) {
    unsigned char raw[8];
    const auto n = static_cast<std::size_t>(t.bytes);
    for (std::size_t j = 0; j < n; ++j)
      raw[j] = static_cast<unsigned char>(text[at + (swap ? n - 1 - j : j)]);
    at += n;
    if (!t.integer) {
      if (n == 4) {
        float f;
        std::memcpy(&f, raw, 4);
        return static_cast<double>(f);
      }
      double d;
      std::memcpy(&d, raw, 8);
      return d;
    }
    std::uint64_t u = 0;  // raw holds the value in host (little-endian) order
    for (std::size_t j = n; j-- > 0;) u = (u << 8) | raw[j];
    long long v = static_cast<long long>(u);
    if (t.is_signed && (u >> (8 * n - 1)) != 0) v -= static_cast<long long>(1ULL << (8 * n));
    return static_cast<double>(v);
  };
  for (const PlyElement& e : h.elements) {
    const bool vertex = e.name == "vertex";
    for (long long i = 0; i < e.count; ++i) {
      const auto bad = [&](const std::string& what) {
        throw InputError(where, "byte " + std::to_string(at - h.body) + " of the body",
                         "malformed binary PLY (" + shown(e.name) + " element " +
                             std::to_string(i) + " of " + std::to_string(e.count) + "): " + what);
      };
      for (const PlyProperty& p : e.properties) {
        if (!p.list) {
          if (size - at < static_cast<std::size_t>(p.value.bytes))
            bad("the file ends before the elements the header announces");
          const double v = value(p.value);
          if (p.role != Role::Skip) out.coordinate(p.role, v);
          continue;
        }
        if (size - at < static_cast<std::size_t>(p.count.bytes))
          bad("the file ends before the elements the header announces");
        const auto c = static_cast<long long>(value(p.count));
        if (c < 0) bad("negative list count " + std::to_string(c));
        const auto width = static_cast<std::size_t>(p.value.bytes);
        if ((size - at) / width < static_cast<std::size_t>(c))
          bad("a list announces " + std::to_string(c) + " values, the file has " +
              std::to_string((size - at) / width) + " left");
        if (p.role == Role::Skip) {
          at += static_cast<std::size_t>(c) * width;
          continue;
        }
        ix.clear();
        for (long long j = 0; j < c; ++j) ix.push_back(static_cast<long long>(value(p.value)));
        out.indices(p.role, ix, bad);
      }
      if (vertex) out.end_vertex();
    }
  }
}

}  // namespace

TriangleMesh read_ply(const fs::path& path, const std::string& where) {
  const std::string text = read_file(path);
  Header h = read_header(text, where);
  const long long vertices = assign_roles(h, where);
  TriangleMesh mesh;
  Builder out(vertices, mesh);
  if (h.format == PlyFormat::Ascii)
    read_ascii_body(text, h, out, where);
  else
    read_binary_body(text, h, out, where);
  return mesh;
}

}  // namespace clumpkit::detail
