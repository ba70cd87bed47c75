// Text made safe for a terminal line or a CSV field; see utf8.h.
#include "labs/utf8.h"

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace dyn {

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

}  // namespace dyn
