// UTF-8 well-formedness, below every layer that reads text (physics/model_file's model files, labs/'
// JSON and its escaping for terminals and CSV in labs/utf8.h): where a text stops being well-formed
// UTF-8 (for "byte 0xE9 at offset N is not valid UTF-8"), a quotable copy with every invalid byte
// written as \xNN, a clipped copy cut between characters, and a walk over the characters. A
// well-formed sequence is one of Unicode's Table 3-7: no overlongs, no surrogates, nothing past
// U+10FFFF, no sequence cut off at the end.
#pragma once
#include <cstddef>
#include <string>
#include <string_view>

namespace dyn {

// Offset of the first byte that does not start or continue a well-formed UTF-8 sequence; npos if none.
std::size_t utf8ErrorAt(std::string_view bytes);

// bytes with each byte of an ill-formed sequence written as the four characters \xNN (so an error
// message quoting a file name is itself valid UTF-8: JSON dump() never throws).
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

}  // namespace dyn
