// UTF-8 well-formedness; see util/utf8.h.
#include "physics/util/utf8.h"

#include <cstdio>
#include <string>

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
