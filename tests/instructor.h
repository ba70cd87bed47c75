// The course staff's files (labs/LAB/instructor/: full-credit submissions) are left out of a student
// copy of the repository (`git archive`, export-ignore in .gitattributes). The few test cases that
// need a full-credit submission are marked `* doctest::skip(!dyn::test::instructorFilesPresent())`:
// skipped in a student copy, run (and able to fail) in the staff's. Every other test uses the
// students' examples or gains that are not the answer.
#pragma once
#include <filesystem>
#include <string>

namespace dyn::test {

// labs/LAB/instructor/ in the source tree (with its trailing slash).
inline std::string instructorDir(const std::string& lab) {
  return std::string(DYNLAB_SOURCE_DIR) + "/labs/" + lab + "/instructor/";
}

// True in the staff's copy: some lab has its instructor folder (a student copy has none at all).
// A staff copy missing one that a test reads fails that test, as it should.
inline bool instructorFilesPresent() {
  std::error_code ec;
  for (const auto& lab : std::filesystem::directory_iterator(std::string(DYNLAB_SOURCE_DIR) + "/labs", ec))
    if (std::filesystem::is_directory(lab.path() / "instructor", ec)) return true;
  return false;
}

}  // namespace dyn::test
