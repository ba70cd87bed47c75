// The escaping functions of every output format; see escape.h.
#include "grading/escape.h"

#include "labs/utf8.h"

#include <algorithm>
#include <cctype>
#include <cstdio>

namespace dyn {
namespace {

constexpr std::string_view kReplacement = "\xEF\xBF\xBD";  // U+FFFD

// The length of the well-formed UTF-8 sequence starting at s[i] (0 if there is none) and its code point.
std::size_t utf8At(std::string_view s, std::size_t i, char32_t& cp) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char b = byte(i);
  if (b < 0x80) return cp = b, 1;
  std::size_t n;
  char32_t min;
  if (b >= 0xC2 && b <= 0xDF) n = 2, cp = b & 0x1F, min = 0x80;
  else if (b >= 0xE0 && b <= 0xEF) n = 3, cp = b & 0x0F, min = 0x800;
  else if (b >= 0xF0 && b <= 0xF4) n = 4, cp = b & 0x07, min = 0x10000;
  else return 0;
  if (i + n > s.size()) return 0;
  for (std::size_t k = 1; k < n; ++k) {
    if ((byte(i + k) & 0xC0) != 0x80) return 0;
    cp = (cp << 6) | (byte(i + k) & 0x3F);
  }
  if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return 0;
  return n;
}

// Calls each(cp, bytes) per well-formed character and bad(byte) per byte that is not part of one.
template <class Each, class Bad>
void forEachChar(std::string_view s, Each each, Bad bad) {
  for (std::size_t i = 0; i < s.size();) {
    char32_t cp = 0;
    if (const std::size_t n = utf8At(s, i, cp)) {
      each(cp, s.substr(i, n));
      i += n;
    } else {
      bad(static_cast<unsigned char>(s[i]));
      ++i;
    }
  }
}

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

// s as valid UTF-8 on one line: controls and invisible controls as escapes, bad bytes as U+FFFD
// (bad_as_hex false) or \xNN (true).
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
      [&](unsigned char b) { out += bad_as_hex ? hexByte(b) : std::string(kReplacement); });
  return out;
}

bool isAsciiPunct(char c) {
  return (c >= '!' && c <= '/') || (c >= ':' && c <= '@') || (c >= '[' && c <= '`') || (c >= '{' && c <= '~');
}

}  // namespace

bool isValidUtf8(std::string_view bytes) { return utf8ErrorAt(bytes) == std::string_view::npos; }

std::string jsonText(std::string_view bytes) {
  if (isValidUtf8(bytes)) return std::string(bytes);
  std::string out;
  forEachChar(bytes, [&](char32_t, std::string_view c) { out += c; }, [&](unsigned char) { out += kReplacement; });
  return out;
}

nlohmann::json jsonSanitized(const nlohmann::json& v) {
  if (v.is_string()) return jsonText(v.get_ref<const std::string&>());
  if (v.is_array()) {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& e : v) out.push_back(jsonSanitized(e));
    return out;
  }
  if (v.is_object()) {
    nlohmann::json out = nlohmann::json::object();
    for (const auto& [k, e] : v.items()) out[jsonText(k)] = jsonSanitized(e);
    return out;
  }
  return v;
}

std::string dumpJson(const nlohmann::json& v, int indent) {
  return v.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::string mdText(std::string_view s) {
  // Punctuation that starts no Markdown construct in the middle of a line stays readable: "[-5, 5]",
  // kp_x, (ζ = 0.7). Escaped: what could start emphasis, code, strikethrough or a table cell, a
  // leading block marker (# - + > = …), . or ) after leading digits (an ordered list), ] before
  // ( [ or : (a link or a reference definition), _ outside a word; < > & become entities.
  constexpr std::string_view kPlain = ".,:;?/'\"%=()-+!@$^{}[]#", kLineStart = "#-+*>=`~|:!_[";
  const auto alnum = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0; };
  const std::string line = visibleLine(s, false);
  std::string out;
  bool digits_only = true;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i], next = i + 1 < line.size() ? line[i + 1] : '\0';
    const bool list_marker = (c == '.' || c == ')') && digits_only && i > 0;
    digits_only = digits_only && c >= '0' && c <= '9';
    if (c == '<' || c == '>' || c == '&') {  // entities: not even the source holds a tag
      out += c == '<' ? "&lt;" : c == '>' ? "&gt;" : "&amp;";
      continue;
    }
    const bool in_word = c == '_' && i > 0 && alnum(line[i - 1]) && alnum(next);
    const bool opens_link = c == ']' && (next == '(' || next == '[' || next == ':');
    // An autolinker keys on "://", "www." and "@": escaping that character (the escape is its own
    // token in CommonMark/GFM and markdown-it) leaves a URL in reflected text inert. GFM finds an
    // email inside the text an escape merges back into, so an empty comment splits the text before
    // its "@" (shown as nothing; the address has no local part left to link; a leading "@" has none).
    const auto lower = [](char ch) { return char(std::tolower(static_cast<unsigned char>(ch))); };
    const bool www = c == '.' && i >= 3 && lower(line[i - 1]) == 'w' && lower(line[i - 2]) == 'w' && lower(line[i - 3]) == 'w';
    const bool links = (c == ':' && line.compare(i + 1, 2, "//") == 0) || www || c == '@';
    const bool plain = (kPlain.find(c) != std::string_view::npos || in_word) && !links;
    if (c == '@' && i > 0) out += "<!-- -->";  // (never first: a line that starts "<!--" is an HTML block)
    if (isAsciiPunct(c) && (!plain || list_marker || opens_link || (i == 0 && kLineStart.find(c) != std::string_view::npos)))
      out += '\\';
    out += c;
  }
  return out;
}

std::string mdCode(std::string_view s) {
  std::string body;
  for (char c : visibleLine(s, false)) {
    if (c == '|') body += '\\';  // GFM splits table cells before code spans; \| stays a | inside them
    body += c;
  }
  std::size_t longest = 0, run = 0;
  for (char c : body) longest = std::max(longest, run = c == '`' ? run + 1 : 0);
  const std::string fence(longest + 1, '`');
  // A space on both sides keeps a leading or trailing backtick out of the fence (CommonMark strips one).
  const bool pad = body.empty() || body.front() == '`' || body.back() == '`' || body.front() == ' ';
  return fence + (pad ? " " : "") + body + (pad ? " " : "") + fence;
}

std::string htmlText(std::string_view s) {
  std::string out;
  for (char c : jsonText(s)) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string termText(std::string_view s) { return visibleLine(s, true); }

std::string shellWord(std::string_view s) {
  const std::string text = jsonText(s);
  const bool plain = !text.empty() && text.find_first_not_of(
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789._/+-") == std::string::npos && text[0] != '-';
  if (plain) return text;
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
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
      [&](unsigned char) { s += kReplacement; });
  if (!s.empty() && (s[0] == '=' || s[0] == '+' || s[0] == '-' || s[0] == '@' || s[0] == '\t' || s[0] == '\r'))
    s.insert(s.begin(), '\'');
  const bool quote = s.find_first_of(",\"\r\n") != std::string::npos || (!s.empty() && (s.front() == ' ' || s.back() == ' '));
  if (!quote) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}


}  // namespace dyn
