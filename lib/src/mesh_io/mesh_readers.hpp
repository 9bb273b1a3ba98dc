#pragma once
// The mesh formats clumpkit reads itself. assimp 5.2 (Debian's libassimp5) is not safe on PLY and
// OFF: the fuzzer found inputs on which it loops forever, abort()s, crashes or asks for ~100 GB.
// Its PLY parser re-reads stale bytes of earlier header lines as new elements, so no check in
// front of it can tell what it will do (a comment line after a longer obj_info line became an
// element of 4 294 967 295 instances). Both formats are simple enough to read completely here;
// assimp reads STL and OBJ.
#include <charconv>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "clumpkit/mesh_io/triangle_mesh.hpp"

namespace clumpkit::detail {

/// A word of the file quoted for an error message: bytes that are not printable ASCII become '?'
/// and a long word is cut (a binary file misread as text must not garble the one-line message).
inline std::string shown(std::string_view word) {
  std::string s = "'";
  for (std::size_t i = 0; i < word.size() && i < 40; ++i) {
    const auto c = static_cast<unsigned char>(word[i]);
    s += c >= 0x20 && c < 0x7f ? static_cast<char>(c) : '?';
  }
  return s + (word.size() > 40 ? "...'" : "'");
}

/// Walks a file's text line by line ('\n'-terminated), handing out each line's words as views
/// into the text, split on blanks (space, tab, CR, VT, FF); with `hash_comments` a '#' ends a
/// line's words (OFF). Counts lines, blank ones included, for error messages; starts at byte
/// `offset`, which follows line `line`.
class TextLines {
 public:
  TextLines(const std::string& text, bool hash_comments, std::size_t offset = 0, int line = 0)
      : text_(text), hash_comments_(hash_comments), at_(offset), line_(line) {}

  /// The words of the next line that has any (blank lines skipped); false at the end.
  bool next(std::vector<std::string_view>& words) {
    words.clear();
    while (at_ < text_.size() && words.empty()) {
      const std::size_t nl = text_.find('\n', at_);
      const std::size_t stop = nl == std::string::npos ? text_.size() : nl;
      split(std::string_view(text_).substr(at_, stop - at_), words);
      at_ = nl == std::string::npos ? text_.size() : nl + 1;
      ++line_;
    }
    return !words.empty();
  }
  int line() const { return line_; }          ///< of the last line read, from 1
  std::size_t offset() const { return at_; }  ///< of the first byte after it

 private:
  void split(std::string_view line, std::vector<std::string_view>& words) const {
    const auto blank = [](char c) {
      return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
    };
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && blank(line[i])) ++i;
      if (hash_comments_ && i < line.size() && line[i] == '#') return;
      const std::size_t b = i;
      while (i < line.size() && !blank(line[i]) && !(hash_comments_ && line[i] == '#')) ++i;
      if (i > b) words.push_back(line.substr(b, i - b));
    }
  }
  const std::string& text_;
  bool hash_comments_;
  std::size_t at_;
  int line_;
};

/// A whole word as a number, as strtod reads it (from_chars first: the same value where both
/// read it, and ~10x faster on a scan's millions of values); false if any of it is left over.
inline bool whole_number(std::string_view word, double& v) {
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), v);
  if (ec == std::errc() && end == word.data() + word.size()) return true;
  const std::string copy(word);  // what from_chars does not take: '+', hex, out of range
  char* stop = nullptr;
  v = std::strtod(copy.c_str(), &stop);
  return stop != copy.c_str() && *stop == '\0';
}

/// A whole word as a base-10 integer (an optional '-', digits); false otherwise.
inline bool whole_integer(std::string_view word, long long& v) {
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), v);
  return ec == std::errc() && end == word.data() + word.size();
}

/// PLY: ASCII and both binary byte orders, every scalar type. The 'vertex' element's x, y, z and
/// the 'face' element's vertex_indices (or vertex_index) list, polygons fanned into triangles;
/// a 'tristrips' element's strips (-1 restarts a strip) are read too, other elements skipped.
/// Vertices are as in the file (unscaled). Throws InputError naming the file and the header
/// line, body line (ASCII) or body byte (binary) of the first defect: unknown keywords or types,
/// counts the body does not hold, non-numbers, indices naming no vertex.
TriangleMesh read_ply(const std::filesystem::path& path, const std::string& where);

/// OFF (also COFF, NOFF, STOFF...: extra values after a vertex's x y z or a face's indices are
/// ignored): '#' comments and blank lines anywhere, counts on the header line or the next one,
/// one vertex and one face per line, polygons fanned. Throws InputError naming the file and line
/// of the first defect; 4OFF, nOFF and binary OFF are refused as unsupported.
TriangleMesh read_off(const std::filesystem::path& path, const std::string& where);

}  // namespace clumpkit::detail
