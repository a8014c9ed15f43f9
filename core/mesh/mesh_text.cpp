#include "core/mesh/mesh_text.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <climits>
#include <system_error>

#include "core/base/errors.h"

namespace qs::mesh_detail {

std::string lowercase(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string uppercase(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

std::string_view skip_utf8_bom(std::string_view text) {
  constexpr std::string_view kBom = "\xEF\xBB\xBF";
  if (text.substr(0, kBom.size()) == kBom) text.remove_prefix(kBom.size());
  return text;
}

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

void tokenize(std::string_view line, std::vector<std::string_view>& tokens) {
  tokens.clear();
  const std::size_t hash = line.find('#');
  if (hash != std::string_view::npos) line = line.substr(0, hash);
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_space(line[i])) ++i;
    const std::size_t begin = i;
    while (i < line.size() && !is_space(line[i])) ++i;
    if (i > begin) tokens.push_back(line.substr(begin, i - begin));
  }
}

bool LineReader::next(std::string_view& line) {
  if (pos_ >= text_.size()) return false;
  std::size_t end = text_.find('\n', pos_);
  unterminated_ = end == std::string_view::npos;
  if (unterminated_) end = text_.size();
  line = text_.substr(pos_, end - pos_);
  pos_ = end + 1;
  ++number_;
  return true;
}

void LineReader::restore(const State& s) {
  pos_ = s.pos;
  number_ = s.number;
  unterminated_ = s.unterminated;
}

void ParseErrors::add(const LineReader& lines, const std::string& what) {
  add(lines.number(),
      what +
          (lines.unterminated() ? " (the file ends in the middle of this line: truncated?)" : ""));
}

void ParseErrors::add(int line, const std::string& what) {
  if (count_++ < kMaxListedErrors) {
    messages_.push_back(path_ + ":" + std::to_string(line) + ": " + what);
  }
}

void ParseErrors::throw_if_any() const {
  if (count_ == 0) return;
  std::string text;
  for (const auto& m : messages_) text += (text.empty() ? "" : "\n") + m;
  if (count_ > messages_.size()) {
    text += "\n" + path_ + ": … and " + std::to_string(count_ - messages_.size()) + " more errors";
  }
  throw InvalidInputError(text);
}

NumberStatus parse_double(std::string_view token, double& value) {
  if (!token.empty() && token[0] == '+') token.remove_prefix(1);  // from_chars rejects '+'
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (ec == std::errc::result_out_of_range) return NumberStatus::kOutOfRange;
  if (ec != std::errc() || end != token.data() + token.size() || token.empty()) {
    return NumberStatus::kNotANumber;
  }
  return NumberStatus::kOk;
}

NumberStatus parse_integer(std::string_view token, long long& value) {
  if (!token.empty() && token[0] == '+') token.remove_prefix(1);
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (ec == std::errc::result_out_of_range) return NumberStatus::kOutOfRange;
  if (ec != std::errc() || end != token.data() + token.size() || token.empty()) {
    return NumberStatus::kNotANumber;
  }
  return NumberStatus::kOk;
}

std::string quoted(std::string_view token) {
  return "'" + std::string(token) + "'";
}

bool parse_point(const std::vector<std::string_view>& tokens, std::size_t first, Vec3& p,
                 ParseErrors& errors, const LineReader& lines) {
  bool ok = true;
  for (int k = 0; k < 3; ++k) {
    const std::string_view t = tokens[first + k];
    switch (parse_double(t, p[k])) {
      case NumberStatus::kOk:
        break;
      case NumberStatus::kNotANumber:
        errors.add(lines, "coordinate " + quoted(t) + " is not a number");
        ok = false;
        break;
      case NumberStatus::kOutOfRange:
        errors.add(lines, "coordinate " + quoted(t) + " is out of the double range");
        ok = false;
        break;
    }
  }
  return ok;
}

int clamp_index(long long index) {
  return static_cast<int>(std::clamp<long long>(index, INT_MIN, INT_MAX));
}

std::string plural(std::size_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

}  // namespace qs::mesh_detail
