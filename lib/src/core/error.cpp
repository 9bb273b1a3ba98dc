#include "clumpkit/core/error.hpp"

namespace clumpkit {

namespace {
std::string compose(const std::string& where, const std::string& field, const std::string& what) {
  std::string s;
  if (!where.empty()) s += where + ": ";
  if (!field.empty()) s += field + ": ";
  return s + what;
}
}  // namespace

InputError::InputError(std::string where, std::string field, const std::string& what)
    : std::runtime_error(compose(where, field, what)), where_(std::move(where)),
      field_(std::move(field)), message_(what) {}

}  // namespace clumpkit
