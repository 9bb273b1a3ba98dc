#pragma once
/// Errors caused by user input. The CLI catches InputError, prints what() on one line and exits 2.
/// Programmer errors are asserts, never InputError.
#include <stdexcept>
#include <string>

namespace clumpkit {

class InputError : public std::runtime_error {
 public:
  /// `where` names the file (optionally file:line), `field` the offending key or column; either
  /// may be empty. The message reads "where: field: what".
  InputError(std::string where, std::string field, const std::string& what);
  explicit InputError(const std::string& what) : InputError("", "", what) {}

  const std::string& where() const { return where_; }
  const std::string& field() const { return field_; }
  const std::string& message() const { return message_; }
  /// The same error, attributed to another file (when a library call did not know it).
  InputError at(const std::string& where) const { return InputError(where, field_, message_); }

 private:
  std::string where_, field_, message_;
};

/// A simulation that became unphysical (NaN, blow-up). Also exits 2, with a diagnosis.
class NumericalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace clumpkit
