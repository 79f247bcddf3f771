// include/fesd/error.hpp: exceptions thrown for bad input, before any computation starts.
//
// What the numerics do (a homotopy that stalls, IPOPT that fails) is never an exception: it is a
// fesd::Status in the result. Exceptions are for input the caller can fix: wrong sizes, NaN,
// options out of range, malformed problem files. Every message names the offending field.
#pragma once
#include <stdexcept>
#include <string>

namespace fesd {

/// Base class of every exception fesd throws.
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

/// An internal invariant of fesd failed: a bug, not bad input (CLI exit code 4).
class InternalError : public Error {
 public:
  using Error::Error;
};

/// Writing an output file failed.
class IoError : public Error {
 public:
  using Error::Error;
};

}  // namespace fesd
