#include "clumpkit/core/error.hpp"

namespace clumpkit {

namespace {
// The CLI prints what() as one line on stderr: control characters that came from user input (a
// newline inside a quoted TOML string, a tab, binary garbage) are escaped.
std::string printable(const std::string& s) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(s.size());
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '\n') {
      out += "\\n";
    } else if (c == '\t') {
      out += "\\t";
    } else if (c < 0x20 || c == 0x7f) {
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
    } else {
      out += ch;
    }
  }
  return out;
}

std::string compose(const std::string& where, const std::string& field, const std::string& what) {
  std::string s;
  if (!where.empty()) s += where + ": ";
  if (!field.empty()) s += field + ": ";
  return printable(s + what);
}
}  // namespace

InputError::InputError(std::string where, std::string field, const std::string& what)
    : std::runtime_error(compose(where, field, what)),
      where_(std::move(where)),
      field_(std::move(field)),
      message_(what) {}

}  // namespace clumpkit
