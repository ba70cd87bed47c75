// Which file of an upload is the submission: one rule for `dynlab grade --batch` (each student's
// folder of a Gradescope export, and each *.json at its top) and for run_autograder (which asks
// `dynlab submission-file DIR`), so the two graders always read the same file or refuse alike.
#pragma once
#include <filesystem>
#include <string>

namespace dyn::app {

struct SubmissionFile {
  std::filesystem::path file;  // the file to grade (a link inside the upload already resolved); empty on a problem
  std::string name;            // its path relative to the folder, as uploaded ("lab3/gains.json")
  std::string problem;         // why there is none: fixed text for the student, naming no server path
};

// The rule. Candidates: every entry below DIR whose name ends in .json (any case) that is not a
// folder, skipping hidden entries and everything under hidden folders (.vscode/settings.json,
// .git/, ._* AppleDouble copies) and __MACOSX/; symlinked folders are not entered. The choice:
// the shallowest file named submission.json (when it is the only one at its depth), else the only
// candidate, else none ("no JSON file" / "several JSON files"). The chosen entry is then checked.
SubmissionFile chooseSubmissionFile(const std::filesystem::path& dir);

// The check every submission file passes before it is read: a link must resolve to somewhere inside
// `root` (the upload), and what it is (or resolves to) must be a regular file, not a FIFO, device,
// socket or folder. Returns the problem ("" when the file may be read); `resolved` gets the real path.
std::string refusedSubmissionFile(const std::filesystem::path& file, const std::filesystem::path& root,
                                  std::filesystem::path& resolved);

// dynlab submission-file DIR: prints the chosen file's path (exit 0), or the problem (exit 2).
int printSubmissionFile(const std::string& dir);

}  // namespace dyn::app
