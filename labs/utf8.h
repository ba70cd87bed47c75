// UTF-8 checks for input: where a text stops being well-formed UTF-8 (for "byte 0xE9 at offset N
// is not valid UTF-8"), and a quotable copy of a name or value with every invalid byte written as
// \xNN, so an error message quoting a file name is itself valid UTF-8 (JSON dump() never throws).
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

}  // namespace dyn
