#pragma once
// Checks run on a mesh file before assimp sees it. assimp 5.2 (Debian's libassimp5) trusts the
// counts in a file: the fuzzer found PLY and OFF inputs on which it loops forever, abort()s,
// crashes or asks for tens of GB. These checks read the formats where that happens far enough to
// refuse such a file with an InputError naming the file and line, so assimp only ever reads files
// whose counts are consistent with their contents.
#include <filesystem>
#include <string>

namespace clumpkit::detail {

/// PLY (by extension or a leading "ply" line): the header (keywords, format, property types,
/// element counts no larger than the file) and the body (every element instance present, every
/// list count within its type and within the data that follows it; ASCII and both binary
/// byte orders).
void check_ply(const std::filesystem::path& path, const std::string& where);

/// OFF (by extension): the header, the counts, the vertex lines and the face lines completely.
void check_off(const std::filesystem::path& path, const std::string& where);

}  // namespace clumpkit::detail
