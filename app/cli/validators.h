// CLI11 validators for the numeric options of quadsketch-cli. CLI::Range and
// CLI::PositiveNumber let "nan" through (every comparison with NaN is false); these reject
// NaN and infinities, so that a bad value fails at parse time with a message naming the flag
// ("--steps: must be a finite number in [0, 10000], got -5").
#pragma once

#include <CLI/CLI.hpp>
#include <limits>
#include <string>

namespace qs::cli {

//! A finite number in [lo, hi]; otherwise "must be a finite number in [lo, hi], got <text>".
CLI::Validator finite_in(double lo, double hi);

//! A finite number in (0, hi]; otherwise "must be <what>, got <text>" (or "must be at most
//! <hi>, got <text>" above hi).
CLI::Validator positive_finite(double hi = std::numeric_limits<double>::max(),
                               const std::string& what = "a finite number > 0");

}  // namespace qs::cli
