// util/utf8.h: the one UTF-8 checker (model files and JSON alike) finds the first byte of every kind of
// ill-formed sequence, and quotes it.
#include "physics/util/utf8.h"

#include <doctest/doctest.h>

#include <string>

using namespace dyn;

TEST_CASE("utf8ErrorAt: well-formed text, and the offset of each kind of ill-formed sequence") {
  CHECK(utf8ErrorAt("plain, é, €, 𝄞") == std::string::npos);
  CHECK(utf8ErrorAt("ab\xC0\x80") == 2);            // overlong (C0, C1 never start a sequence)
  CHECK(utf8ErrorAt("ab\xE0\x80\x80") == 2);        // overlong three-byte form
  CHECK(utf8ErrorAt("a\xED\xA0\x80") == 1);         // a surrogate, U+D800
  CHECK(utf8ErrorAt("\xF4\x90\x80\x80") == 0);      // past U+10FFFF
  CHECK(utf8ErrorAt("\xF5\x80\x80\x80") == 0);      // no such lead byte
  CHECK(utf8ErrorAt("ok\xE2\x82") == 2);            // cut off at the end
  CHECK(utf8ErrorAt("x\xE2" "A\xAC") == 1);         // a continuation missing mid-text
  CHECK(utf8ErrorAt("\x80") == 0);                  // a lone continuation byte
}

TEST_CASE("utf8Quotable writes each bad byte as \\xNN and keeps the rest") {
  CHECK(utf8Quotable("caf\xE9!") == "caf\\xE9!");
  CHECK(utf8Quotable("€") == "€");
}
