#include "app/cli/validators.h"

#include <cmath>
#include <limits>
#include <sstream>

namespace qs::cli {

namespace {

std::string number_text(double value) {
  std::ostringstream os;
  os << value;
  return os.str();
}

//! The number in \p text, or NaN when it is none.
double parse_number(const std::string& text) {
  double value = 0;
  return CLI::detail::lexical_cast(text, value) ? value : std::nan("");
}

}  // namespace

CLI::Validator finite_in(double lo, double hi) {
  const std::string range = "in [" + number_text(lo) + ", " + number_text(hi) + "]";
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        const double value = parse_number(text);
        if (std::isfinite(value) && value >= lo && value <= hi) return {};
        return "must be a finite number " + range + ", got " + text;
      },
      "NUMBER " + range);
}

CLI::Validator positive_finite(double hi, const std::string& what) {
  return CLI::Validator(
      [hi, what](std::string& text) -> std::string {
        const double value = parse_number(text);
        if (!std::isfinite(value) || value <= 0) return "must be " + what + ", got " + text;
        if (value > hi) return "must be at most " + number_text(hi) + ", got " + text;
        return {};
      },
      hi < std::numeric_limits<double>::max() ? "NUMBER in (0, " + number_text(hi) + "]"
                                              : std::string("NUMBER > 0"));
}

}  // namespace qs::cli
