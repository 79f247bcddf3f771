// include/fesd/error.hpp: exceptions thrown for bad input, before any computation starts, and the
// one exception for a bug in fesd itself.
//
// What the numerics do (a homotopy that stalls, IPOPT that fails) is never an exception: it is a
// fesd::Status in the result. fesd::Error and its subclasses are for input the caller can fix:
// wrong sizes, NaN, options out of range, malformed problem files. Every message names the
// offending field. fesd::InternalError is not a fesd::Error: it means fesd broke one of its own
// invariants, whatever the input was (please report it). Running out of memory is std::bad_alloc.
// The `fesd` program maps them to exit codes: Error 2 (IoError 3), InternalError and
// std::bad_alloc 4 ("internal error: ...").
#pragma once
#include <stdexcept>
#include <string>

namespace fesd {

/// Base class of every exception fesd throws for bad input (everything but InternalError).
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// An option is out of range or inconsistent ("discretization.n_s = 0: must be >= 1").
class InvalidOption : public Error {
 public:
  using Error::Error;
};

/// A model is malformed: wrong dimensions, sign matrix not +-1, repeated rows, non-finite data.
class InvalidModel : public Error {
 public:
  using Error::Error;
};

/// A problem file cannot be read or is malformed: "file.toml:12: unknown key 'n_S' (did you mean
/// 'n_s'?)".
class ProblemFileError : public Error {
 public:
  using Error::Error;
};

/// A math expression in a problem file does not parse or names an unknown symbol.
class ExpressionError : public Error {
 public:
  using Error::Error;
};

/// Writing an output file failed.
class IoError : public Error {
 public:
  using Error::Error;
};

/// An internal invariant of fesd is broken (a bug, not bad input): "internal: ...". Deliberately
/// not a fesd::Error, so that callers who report fesd::Error as "bad input" do not blame the user.
class InternalError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

}  // namespace fesd
