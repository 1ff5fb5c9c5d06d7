// ctid — error classes of the three error tiers (docs/architecture.md, "Errors").
//
// Tier 1, bad user input: an exception derived from a std exception whose message
// names the thing and the values:
//   * InvalidArgument (std::invalid_argument): wrong sizes, NaN/Inf, non-increasing
//     times, order too high for the data, ...
//   * InvalidOptions (InvalidArgument): an options field out of range; thrown by
//     `Options::validate()` and names the field and its value.
//   * ColumnSelectionError (InvalidArgument): a data column selected that the file does
//     not have, or selected twice.
//   * FileError (std::runtime_error): a file cannot be opened, parsed or written;
//     the message names the path (and line/column where it applies).
// Tier 2, the algorithm did not succeed: no exception, see Summary (status.hpp).
// Tier 3, our own bug: CTID_ASSERT (check.hpp).
#pragma once

#include <stdexcept>
#include <string>
#include <utility>

namespace ctid {

/// Bad input to a library function (sizes, values, data that cannot support the request).
class InvalidArgument : public std::invalid_argument {
 public:
  explicit InvalidArgument(const std::string& what) : std::invalid_argument(what) {}
};

/// An options struct holds a value out of its documented range.
class InvalidOptions : public InvalidArgument {
 public:
  explicit InvalidOptions(const std::string& what) : InvalidArgument(what) {}
};

/// A setting name that the method does not have (a typo, or a setting of another method).
class UnknownSetting : public InvalidOptions {
 public:
  UnknownSetting(const std::string& what, std::string method, std::string key, std::string closest)
      : InvalidOptions(what), method(std::move(method)), key(std::move(key)), closest(std::move(closest)) {}
  std::string method;   ///< the method asked
  std::string key;      ///< the name given
  std::string closest;  ///< the closest setting name of the method, "" when none is close
};
/// A column selection that names no column of the file, or one column twice (a name or 1-based position).
class ColumnSelectionError : public InvalidArgument {
 public:
  explicit ColumnSelectionError(const std::string& what) : InvalidArgument(what) {}
};
/// A file could not be opened, read, parsed or written.
class FileError : public std::runtime_error {
 public:
  explicit FileError(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace ctid
