// Exception hierarchy of QuadSketch. Every error a user can cause is an InvalidInputError
// (CLI exit code 2); numerical failures are SolverError (exit code 3).
#pragma once

#include <stdexcept>
#include <string>

namespace qs {

//! Base of every QuadSketch error.
class QsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

//! Bad input: unreadable or broken file, invalid mesh or layout. CLI exit code 2.
class InvalidInputError : public QsError {
 public:
  using QsError::QsError;
};

//! A layout (or a state of it that an optimizer tries) whose constraints contradict each other,
//! so that no field or parameterization realizes it: the linear constraints of the
//! parameterization reduce to 0 = c ≠ 0 (e.g. prescribed arc lengths that opposite patch sides
//! cannot both have). The node optimizer rejects such a trial state. Exit code 2.
class InfeasibleLayoutError : public InvalidInputError {
 public:
  using InvalidInputError::InvalidInputError;
};

//! A layout whose topology cannot be realized (e.g. inconsistent turning numbers). Exit code 2.
class TopologyError : public InfeasibleLayoutError {
 public:
  using InfeasibleLayoutError::InfeasibleLayoutError;
};

//! A numerical solve failed (not positive definite, non-finite values). CLI exit code 3.
class SolverError : public QsError {
 public:
  using QsError::QsError;
};

//! The running job was cancelled through its Observer.
class Cancelled : public QsError {
 public:
  Cancelled() : QsError("cancelled") {}
};

//! CLI exit code for an exception (0 is never returned here).
inline int exit_code_for(const std::exception& e) {
  if (dynamic_cast<const InvalidInputError*>(&e)) return 2;
  if (dynamic_cast<const SolverError*>(&e)) return 3;
  return 1;
}

}  // namespace qs
