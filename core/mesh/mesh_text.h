// Text helpers shared by the mesh file readers (core/mesh/*_reader.cpp): tokens, numbers,
// line-precise error collection. Internal to core/mesh; the public API is mesh_io.h.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "core/mesh/mesh.h"

namespace qs::mesh_detail {

//! Most errors one ParseErrors lists before it only counts the rest.
constexpr std::size_t kMaxListedErrors = 10;

std::string lowercase(std::string s);
std::string uppercase(std::string s);

//! \p text without a leading UTF-8 byte-order mark (EF BB BF), which some editors write.
std::string_view skip_utf8_bom(std::string_view text);

//! Space, tab, CR, VT or FF (not LF, which ends a line).
bool is_space(char c);

//! Splits a line into whitespace-separated tokens, dropping a trailing "# comment".
void tokenize(std::string_view line, std::vector<std::string_view>& tokens);

//! Walks a buffer line by line (LF or CRLF) and remembers the 1-based line number.
class LineReader {
 public:
  explicit LineReader(std::string_view text) : text_(text) {}

  //! Next line without its LF (a CR before it stays; tokenize treats it as space).
  bool next(std::string_view& line);
  int number() const { return number_; }
  //! True when the current line is the last one and no newline ends it: a cut-off file.
  bool unterminated() const { return unterminated_; }

  //! Position to come back to after looking ahead.
  struct State {
    std::size_t pos;
    int number;
    bool unterminated;
  };
  State state() const { return {pos_, number_, unterminated_}; }
  void restore(const State& s);

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  int number_ = 0;
  bool unterminated_ = false;
};

//! Collects line-precise parse errors ("<path>:<line>: <what>") and throws them together, so
//! one run shows the first few problems of a broken file instead of one at a time.
class ParseErrors {
 public:
  explicit ParseErrors(std::string path) : path_(std::move(path)) {}

  //! An error on the current line of \p lines; notes a cut-off last line.
  void add(const LineReader& lines, const std::string& what);
  void add(int line, const std::string& what);
  //! \throw InvalidInputError with every collected message (at most kMaxListedErrors lines
  //!        plus a count of the rest) when there is any.
  void throw_if_any() const;

 private:
  std::string path_;
  std::vector<std::string> messages_;
  std::size_t count_ = 0;
};

enum class NumberStatus { kOk, kNotANumber, kOutOfRange };

//! Whole-token conversions (a leading '+' is accepted; trailing characters are not).
NumberStatus parse_double(std::string_view token, double& value);
NumberStatus parse_integer(std::string_view token, long long& value);

//! "'token'".
std::string quoted(std::string_view token);

//! Parses tokens[first .. first + 2] as x, y, z into \p p; reports bad numbers on the current
//! line of \p lines and returns false.
bool parse_point(const std::vector<std::string_view>& tokens, std::size_t first, Vec3& p,
                 ParseErrors& errors, const LineReader& lines);

//! Stores an index that may be out of range as an int the mesh builder will flag.
int clamp_index(long long index);

//! "1 vertex", "3 vertices".
std::string plural(std::size_t n, const char* one, const char* many);

}  // namespace qs::mesh_detail
