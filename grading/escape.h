// One escaping function per output format. Every piece of text a user controls (submission file
// names, JSON string values and keys, error messages quoting input) goes through the function of
// the format it lands in, and only there:
//   JSON      jsonText (valid UTF-8; nlohmann escapes the rest) and dumpJson (a dump that cannot throw)
//   Markdown  mdText (inline text, every ASCII punctuation backslash-escaped) and mdCode (a code span)
//   HTML      htmlText (& < > " ' as entities)
//   terminal  termText (control characters, bidi overrides and invalid bytes as visible escapes)
//   CSV       csvField (RFC 4180 quoting; formula lead characters neutralised)
//   shell     shellWord (a file name in a command to copy)
// Each returns valid UTF-8 whatever the input: an invalid byte becomes U+FFFD.
#pragma once
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "labs/utf8.h"

namespace dyn {

// True when bytes are well-formed UTF-8 (no overlongs, surrogates or code points past U+10FFFF).
bool isValidUtf8(std::string_view bytes);

// bytes with every byte that is not part of a well-formed UTF-8 sequence replaced by U+FFFD.
std::string jsonText(std::string_view bytes);

// A copy of v with every string value and object key passed through jsonText.
nlohmann::json jsonSanitized(const nlohmann::json& v);

// v.dump(indent) that replaces invalid UTF-8 instead of throwing (the second line of defence).
std::string dumpJson(const nlohmann::json& v, int indent = -1);

// Text for a Markdown line or table cell: ASCII punctuation that could start a construct is
// backslash-escaped (no emphasis, link, code, HTML, entity, heading, quote or list marker can
// start; < > & become entities, so not even the source holds a tag), line breaks and other control
// characters shown as \n, \r, \xNN: one value, one line. URLs and emails are inert: the ":" of
// "://" and the "." of "www." are escaped, and an empty comment splits the text before every "@"
// (cmark-gfm links an email across a backslash escape).
std::string mdText(std::string_view s);

// An inline code span holding s literally: fenced by a backtick run longer than any inside, control
// characters shown as \n, \xNN; a | is escaped so the span can sit in a table cell. Markup inside
// stays text when rendered, but is there in the source: for names from the lab's own config.
std::string mdCode(std::string_view s);

// Text for HTML element content or a quoted attribute value.
std::string htmlText(std::string_view s);

// termText (one line for a terminal) and termName (a name from a file, escaped and clipped):
// labs/utf8.h, so that labs/ and render/ use the same function.

// A word for a POSIX shell command line shown to a user: as it is when plain, else '...' quoted.
std::string shellWord(std::string_view s);

// csvField (one CSV field, no formula, controls as escapes): labs/utf8.h.

// clipText (text echoed from input, at most so many bytes): labs/utf8.h.

}  // namespace dyn
