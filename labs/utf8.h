// The escaping of text for a terminal line and a CSV field (grading/escape.h names every format's
// function; these live here so that labs/ and render/ can use them too), over the UTF-8 checks of
// util/utf8.h (included: where text stops being well-formed, a quotable copy, a clipped copy).
#pragma once
#include <cstddef>
#include <string>
#include <string_view>

#include "physics/util/utf8.h"

namespace dyn {

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
