// The escaping functions of every output format; see escape.h.
#include "grading/escape.h"

#include "labs/utf8.h"

#include <algorithm>
#include <cctype>

namespace dyn {
namespace {

bool isAsciiPunct(char c) {
  return (c >= '!' && c <= '/') || (c >= ':' && c <= '@') || (c >= '[' && c <= '`') || (c >= '{' && c <= '~');
}

}  // namespace

bool isValidUtf8(std::string_view bytes) { return utf8ErrorAt(bytes) == std::string_view::npos; }

std::string jsonText(std::string_view bytes) {
  if (isValidUtf8(bytes)) return std::string(bytes);
  std::string out;
  forEachChar(bytes, [&](char32_t, std::string_view c) { out += c; }, [&](unsigned char) { out += kReplacementChar; });
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

std::string shellWord(std::string_view s) {
  const std::string text = jsonText(s);
  const bool plain = !text.empty() && text.find_first_not_of(
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789._/+-") == std::string::npos && text[0] != '-';
  if (plain) return text;
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

}  // namespace dyn
