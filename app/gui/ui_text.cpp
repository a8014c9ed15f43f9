#include "app/gui/ui_text.h"

#include <cstdint>
#include <utility>

namespace qs::app {

namespace {

bool g_unicode = true;

// ASCII stand-ins for the characters beyond ASCII that messages and labels use.
const std::pair<std::uint32_t, const char*> kAscii[] = {
    {0x00B0, " deg"},  {0x00B1, "+/-"},    {0x00B2, "^2"},    {0x00B7, "."},     {0x00D7, "x"},
    {0x03B1, "alpha"}, {0x03B5, "eps"},    {0x03B8, "theta"}, {0x03C3, "sigma"}, {0x03A6, "Phi"},
    {0x03C6, "phi"},   {0x03BB, "lambda"}, {0x2013, "-"},     {0x2014, "-"},     {0x2018, "'"},
    {0x2019, "'"},     {0x201C, "\""},     {0x201D, "\""},    {0x2026, "..."},   {0x2032, "'"},
    {0x2113, "l"},     {0x2190, "<-"},     {0x2192, "->"},    {0x2194, "<->"},   {0x21D2, "=>"},
    {0x2202, "d"},     {0x2207, "grad"},   {0x2212, "-"},     {0x221A, "sqrt"},  {0x221E, "inf"},
    {0x2248, "~"},     {0x2260, "!="},     {0x2264, "<="},    {0x2265, ">="},    {0x2308, "ceil("},
    {0x2309, ")"},     {0x230A, "floor("}, {0x230B, ")"},     {0x2016, "||"},    {0x00A7, "S"},
};

// Decodes the UTF-8 sequence at text[i]; advances i. Invalid bytes decode as U+FFFD.
std::uint32_t decode(const std::string& text, std::size_t& i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char c = byte(i);
  int extra = 0;
  std::uint32_t cp = 0;
  if (c < 0x80) {
    ++i;
    return c;
  } else if ((c & 0xE0) == 0xC0) {
    extra = 1;
    cp = c & 0x1F;
  } else if ((c & 0xF0) == 0xE0) {
    extra = 2;
    cp = c & 0x0F;
  } else if ((c & 0xF8) == 0xF0) {
    extra = 3;
    cp = c & 0x07;
  } else {
    ++i;
    return 0xFFFD;
  }
  if (i + extra >= text.size()) {  // truncated at the end
    i = text.size();
    return 0xFFFD;
  }
  for (int k = 1; k <= extra; ++k) {
    if ((byte(i + k) & 0xC0) != 0x80) {
      i += k;
      return 0xFFFD;
    }
    cp = (cp << 6) | (byte(i + k) & 0x3F);
  }
  i += extra + 1;
  return cp;
}

}  // namespace

void set_unicode_text(bool unicode) {
  g_unicode = unicode;
}

bool unicode_text() {
  return g_unicode;
}

std::string ascii_text(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    const std::uint32_t cp = decode(text, i);
    if (cp < 0x80) {
      out += char(cp);
      continue;
    }
    const char* replacement = "?";
    for (const auto& [code, ascii] : kAscii)
      if (code == cp) replacement = ascii;
    out += replacement;
  }
  return out;
}

std::string ui_text(const std::string& text) {
  if (g_unicode) return text;
  for (unsigned char c : text)
    if (c >= 0x80) return ascii_text(text);
  return text;
}

}  // namespace qs::app
