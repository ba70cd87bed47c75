// UTF-8 checks for input: where a text stops being well-formed UTF-8 (for "byte 0xE9 at offset N
// is not valid UTF-8"), and a quotable copy of a name or value with every invalid byte written as
// \xNN, so an error message quoting a file name is itself valid UTF-8 (JSON dump() never throws).
// Also the escaping of text for a terminal line and a CSV field (grading/escape.h names every
// format's function; these two live here so that labs/ and render/ can use them too).
#pragma once
#include <cstddef>
#include <string>
#include <string_view>

namespace dyn {

// Offset of the first byte that does not start or continue a well-formed UTF-8 sequence (no
// overlongs, no surrogates, nothing past U+10FFFF, no sequence cut off at the end); npos if none.
std::size_t utf8ErrorAt(std::string_view bytes);

// bytes with each byte of an ill-formed sequence written as the four characters \xNN.
std::string utf8Quotable(std::string_view bytes);

// Text echoed from input (a key, a value, a message quoting them), at most max_bytes: a longer one
// keeps its head and tail, cut at character boundaries, joined by " … " and the count of bytes left
// out, so a 900 KB key is never quoted whole while the message still names where and what was expected.
std::string clipText(std::string_view s, std::size_t max_bytes = 300);

// The length of the well-formed UTF-8 sequence starting at s[i] (0 if there is none) and, through
// cp, its code point.
std::size_t utf8CharAt(std::string_view s, std::size_t i, char32_t& cp);

// U+FFFD, what an ill-formed byte becomes where text must stay valid UTF-8.
inline constexpr std::string_view kReplacementChar = "\xEF\xBF\xBD";

// Calls each(cp, bytes) per well-formed character of s and bad(byte) per byte that is not part of one.
template <class Each, class Bad>
void forEachChar(std::string_view s, Each each, Bad bad) {
  for (std::size_t i = 0; i < s.size();) {
    char32_t cp = 0;
    if (const std::size_t n = utf8CharAt(s, i, cp)) {
      each(cp, s.substr(i, n));
      i += n;
    } else {
      bad(static_cast<unsigned char>(s[i]));
      ++i;
    }
  }
}

// s as valid UTF-8 on one line: C0 controls and DEL as \n, \r, \t or \xNN, C1 controls, U+2028/
// U+2029 and bidi controls as \u{XXXX}; a byte that is not part of a well-formed character as \xNN
// (bad_as_hex) or U+FFFD.
std::string visibleLine(std::string_view s, bool bad_as_hex);

// One line for a terminal: control characters (C0, DEL, C1), U+2028/U+2029 and bidi controls as
// \n, \t, \xNN or \u{XXXX}; invalid UTF-8 bytes as \xNN.
std::string termText(std::string_view s);

// A name or path that came from a file (a joint, a body, a model file's path), for a terminal line,
// a summary, a report or the window: termText, and when longer than max_bytes its head and tail
// only, cut between characters (never inside an escape) and joined by " … (N bytes left out) … ".
std::string termName(std::string_view s, std::size_t max_bytes = 200);

// One CSV field: control characters other than line breaks and tabs (ESC, OSC, C1) and bidi
// controls shown as escapes (\x1b, \u{202E}), a leading = + - @ tab or CR gets a ' prefix (no
// spreadsheet formula), then the field is quoted when it holds , " CR or LF or starts/ends with a
// space ("" inside). Pass numbers you format yourself directly; this is for text.
std::string csvField(const std::string& s);

}  // namespace dyn
