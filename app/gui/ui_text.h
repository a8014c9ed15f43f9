// Text for the UI font (GL-free). With DejaVu Sans the UI shows the Greek letters, arrows and
// mathematical signs the messages use; with ImGui's built-in font (ASCII and Latin-1 only) they
// would show as '?', so every text is turned into ASCII first.
#pragma once

#include <string>

namespace qs::app {

//! Sets whether the UI font has the glyphs beyond ASCII (false: ui_text() transliterates).
void set_unicode_text(bool unicode);
bool unicode_text();

//! \p text as the UI font can show it: unchanged with the Unicode font, else in ASCII
//! ("−" -> "-", "≠" -> "!=", "→" -> "->", "°" -> " deg", "σ" -> "sigma", ...; other
//! characters beyond ASCII -> "?").
std::string ui_text(const std::string& text);
//! ASCII transliteration of UTF-8 \p text (what ui_text() returns without the Unicode font).
std::string ascii_text(const std::string& text);

}  // namespace qs::app
