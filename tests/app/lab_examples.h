// What the tests that grade every lab's shipped examples share (tests/app/same_bits_test.cpp,
// tests/web/same_grade_test.cpp): a lab's example submissions, and a results.json's text without its
// one value that differs between two runs (the wall time).
#pragma once
#include <algorithm>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>

namespace dyn::test {

inline std::vector<std::filesystem::path> labExamples(const std::string& lab) {
  std::vector<std::filesystem::path> out;
  for (const auto& e : std::filesystem::directory_iterator(std::filesystem::path(DYNLAB_SOURCE_DIR) / "labs" / lab / "examples"))
    if (e.path().extension() == ".json") out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

inline std::string withoutExecutionTime(const std::string& results) {
  return std::regex_replace(results, std::regex(R"("execution_time": [^,\n]*)"), "\"execution_time\": _");
}

}  // namespace dyn::test
