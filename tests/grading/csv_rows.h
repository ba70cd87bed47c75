// A gradebook's CSV read back as RFC 4180 rows, strictly (what the batch tests share): quoted fields
// may hold commas, quotes ("") and line breaks; a quote inside an unquoted field, text after a closing
// quote, an unterminated quoted field or a last line without its line break fails the test.
#pragma once
#include <doctest/doctest.h>

#include <string>
#include <vector>

namespace dyn::test {

inline std::vector<std::vector<std::string>> parseCsv(const std::string& text) {
  std::vector<std::vector<std::string>> rows(1);
  std::string cell;
  bool quoted = false, was_quoted = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted) {
      if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') cell += '"', ++i;
      else if (c == '"') quoted = false;
      else cell += c;
    } else if (c == '"') {
      REQUIRE_MESSAGE(cell.empty(), "a quote inside an unquoted field");
      quoted = was_quoted = true;
    } else if (c == ',' || c == '\n') {
      rows.back().push_back(cell);
      cell.clear();
      was_quoted = false;
      if (c == '\n') rows.emplace_back();
    } else {
      REQUIRE_MESSAGE(!was_quoted, "text after a closing quote");
      cell += c;
    }
  }
  REQUIRE_MESSAGE(!quoted, "an unterminated quoted field");
  REQUIRE_MESSAGE(rows.back().empty(), "the last line has no line break");
  rows.pop_back();
  return rows;
}

}  // namespace dyn::test
