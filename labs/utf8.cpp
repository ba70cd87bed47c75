// UTF-8 validation of input text, and text made safe for a terminal line or a CSV field; see utf8.h.
#include "labs/utf8.h"

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace dyn {

namespace {
// Length of the well-formed sequence starting at i (Unicode Table 3-7), or 0 if it is ill-formed.
std::size_t sequenceAt(std::string_view s, std::size_t i) {
  const auto byte = [&](std::size_t k) { return k < s.size() ? static_cast<unsigned char>(s[k]) : 0u; };
  const unsigned b = byte(i);
  if (b < 0x80) return 1;
  // The second byte's range depends on the first (this is what rules out overlongs and surrogates).
  unsigned lo = 0x80, hi = 0xBF;
  std::size_t n = 0;
  if (b >= 0xC2 && b <= 0xDF) n = 2;
  else if (b >= 0xE0 && b <= 0xEF) n = 3, lo = b == 0xE0 ? 0xA0 : 0x80, hi = b == 0xED ? 0x9F : 0xBF;
  else if (b >= 0xF0 && b <= 0xF4) n = 4, lo = b == 0xF0 ? 0x90 : 0x80, hi = b == 0xF4 ? 0x8F : 0xBF;
  else return 0;
  if (i + n > s.size()) return 0;
  if (byte(i + 1) < lo || byte(i + 1) > hi) return 0;
  for (std::size_t k = 2; k < n; ++k)
    if (byte(i + k) < 0x80 || byte(i + k) > 0xBF) return 0;
  return n;
}
}  // namespace

std::size_t utf8CharAt(std::string_view s, std::size_t i, char32_t& cp) {
  const std::size_t n = sequenceAt(s, i);
  if (n == 0) return 0;
  const unsigned char b = static_cast<unsigned char>(s[i]);
  cp = n == 1 ? b : n == 2 ? (b & 0x1F) : n == 3 ? (b & 0x0F) : (b & 0x07);
  for (std::size_t k = 1; k < n; ++k) cp = (cp << 6) | (static_cast<unsigned char>(s[i + k]) & 0x3F);
  return n;
}

namespace {

std::string hexByte(unsigned b) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "\\x%02X", b);
  return buf;
}

// \n, \r, \t or \xNN for a C0 control or DEL; empty for any other character.
std::string controlEscape(char32_t cp) {
  if (cp == '\n') return "\\n";
  if (cp == '\r') return "\\r";
  if (cp == '\t') return "\\t";
  if (cp < 0x20 || cp == 0x7F) return hexByte(unsigned(cp));
  return {};
}

// Characters that move or hide text on a terminal or in a page: C1 controls, line/paragraph
// separators, bidi embeddings, overrides and isolates.
bool isInvisibleControl(char32_t cp) {
  return (cp >= 0x80 && cp <= 0x9F) || cp == 0x2028 || cp == 0x2029 || (cp >= 0x202A && cp <= 0x202E) ||
         (cp >= 0x2066 && cp <= 0x2069) || cp == 0x200E || cp == 0x200F || cp == 0x061C;
}

std::string codePointEscape(char32_t cp) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "\\u{%04X}", unsigned(cp));
  return buf;
}

}  // namespace

std::string visibleLine(std::string_view s, bool bad_as_hex) {
  std::string out;
  out.reserve(s.size());
  forEachChar(
      s,
      [&](char32_t cp, std::string_view bytes) {
        if (std::string e = controlEscape(cp); !e.empty()) out += e;
        else if (isInvisibleControl(cp)) out += codePointEscape(cp);
        else out += bytes;
      },
      [&](unsigned char b) { out += bad_as_hex ? hexByte(b) : std::string(kReplacementChar); });
  return out;
}

std::string termText(std::string_view s) { return visibleLine(s, true); }

std::string termName(std::string_view s, std::size_t max_bytes) {
  // Escaped character by character, remembering where each one starts in s and in the text, so the
  // cut falls between two characters: never inside an escape such as \u{202E}.
  std::string text;
  std::vector<std::pair<std::size_t, std::size_t>> starts;  // (offset in s, offset in text)
  std::size_t at = 0;
  forEachChar(
      s,
      [&](char32_t, std::string_view bytes) {
        starts.emplace_back(at, text.size());
        text += visibleLine(bytes, true);
        at += bytes.size();
      },
      [&](unsigned char b) {
        starts.emplace_back(at, text.size());
        text += hexByte(b);
        ++at;
      });
  if (text.size() <= max_bytes) return text;
  starts.emplace_back(s.size(), text.size());
  // The head: characters starting up to 2/3 of the room; the tail: from the last third on.
  std::size_t head = 0, tail = starts.size() - 1;
  while (head + 1 < starts.size() && starts[head + 1].second <= max_bytes * 2 / 3) ++head;
  while (tail > head && text.size() - starts[tail - 1].second <= max_bytes / 3) --tail;
  return text.substr(0, starts[head].second) + " … (" + std::to_string(starts[tail].first - starts[head].first) +
         " bytes left out) … " + text.substr(starts[tail].second);
}

std::string csvField(const std::string& raw) {
  // Line breaks and tabs stay (quoted below); other controls (ESC, OSC, bidi overrides) as escapes.
  std::string s;
  forEachChar(
      raw,
      [&](char32_t cp, std::string_view bytes) {
        if (cp == '\n' || cp == '\r' || cp == '\t') s += bytes;
        else if (std::string e = controlEscape(cp); !e.empty()) s += e;
        else if (isInvisibleControl(cp)) s += codePointEscape(cp);
        else s += bytes;
      },
      [&](unsigned char) { s += kReplacementChar; });
  if (!s.empty() && (s[0] == '=' || s[0] == '+' || s[0] == '-' || s[0] == '@' || s[0] == '\t' || s[0] == '\r'))
    s.insert(s.begin(), '\'');
  const bool quote = s.find_first_of(",\"\r\n") != std::string::npos || (!s.empty() && (s.front() == ' ' || s.back() == ' '));
  if (!quote) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::size_t utf8ErrorAt(std::string_view s) {
  for (std::size_t i = 0; i < s.size();) {
    const std::size_t n = sequenceAt(s, i);
    if (n == 0) return i;
    i += n;
  }
  return std::string_view::npos;
}

std::string utf8Quotable(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size();) {
    const std::size_t n = sequenceAt(s, i);
    if (n == 0) {
      char b[8];
      std::snprintf(b, sizeof b, "\\x%02X", static_cast<unsigned char>(s[i]));
      out += b;
      ++i;
    } else {
      out.append(s.substr(i, n));
      i += n;
    }
  }
  return out;
}

std::string clipText(std::string_view s, std::size_t max_bytes) {
  if (s.size() <= max_bytes) return std::string(s);
  // Back off to the start of a UTF-8 character (a continuation byte is 10xxxxxx).
  const auto boundary = [&](std::size_t at) {
    while (at > 0 && at < s.size() && (static_cast<unsigned char>(s[at]) & 0xC0) == 0x80) --at;
    return at;
  };
  const std::size_t head = boundary(max_bytes * 2 / 3), tail = boundary(s.size() - max_bytes / 3);
  return std::string(s.substr(0, head)) + " … (" + std::to_string(tail - head) + " bytes left out) … " +
         std::string(s.substr(tail));
}

}  // namespace dyn
