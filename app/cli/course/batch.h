// dynlab grade --batch, in three parts: finding the submissions and giving each a safe output
// folder (batch_inputs.cpp), running one grader process per submission under a lock on OUT
// (batch.cpp), and turning each result into a gradebook row and the gradebook with its summary
// (batch_gradebook.cpp).
#pragma once
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace dyn::app::batch {

// One submission of a batch: a JSON file at the top of DIR, or one student's folder (Gradescope export).
struct Submission {
  std::string name;            // as the gradebook shows it: "x.json" or "folder/x.json" (raw bytes)
  std::filesystem::path file;  // what the grader reads (empty when `problem` says why there is none)
  std::string problem;         // set when it cannot be graded at all (no file, several, not a regular file)
  std::string folder;          // its output folder's name inside OUT: safe, unique, never OUT's own files
  std::string student;         // whose plant it is graded on (a lab with variants; else empty)
};

// Each submission's student when the lab gives each student their own plant (labs/variants.h): the
// roster's ID for its name (a CSV of lines FILE_OR_FOLDER,STUDENT_ID; a first line
// "submission,student" is a header), else its folder's name or its file's stem. A name that is not a
// student ID (grading/student.h) makes it a problem, naming the roster. Throws InputError for a
// roster that cannot be read (naming the file and line).
void assignStudents(std::vector<Submission>& subs, const std::string& roster);

// What a batch directory holds. `error` is set (and nothing is listed) when it holds no submission.
struct Found {
  std::vector<Submission> submissions;  // sorted by name
  std::string error;
};

// The submissions of DIR: every *.json at its top, and every folder below it as one student's
// submission (its submission.json, else its only *.json). Skipped: macOS __MACOSX/ folders and
// ._* AppleDouble files, hidden folders, and OUT itself when it sits inside DIR.
Found findSubmissions(const std::filesystem::path& dir, const std::filesystem::path& out);

// Gives each submission its output folder: the name reduced to [A-Za-z0-9_.-] (no leading dot or
// dash, at most 60 bytes), plus "-" and 8 hex digits of its hash when that changed it, when two
// names meet (ignoring case), when it could be taken for OUT's gradebook files, or when OUT holds a
// folder of that name that no batch wrote (no grade.log in it).
void assignFolders(std::vector<Submission>& subs, const std::filesystem::path& out);

// One test of a graded row.
struct TestScore {
  std::string name;
  double score = 0, max_score = 0;
};

// One gradebook row.
struct Row {
  std::string name, folder, status, reason;
  double score = 0, max_score = 0;
  bool graded = false;           // max_score comes from its own tests
  std::vector<TestScore> tests;  // in rubric order
  std::string answers;           // the submission's written answers ("name: text", blank-line separated)
};

// A row from OUT/<folder>/results.json after the grader exited with `exit_code` (0 graded, 2 invalid
// submission; anything else is not a grade). Fails over to status "internal error" when the file
// does not say what the exit code promised.
Row rowFromResults(const Submission& s, const std::filesystem::path& results, int exit_code, const std::string& log_tail);

// A row for a submission that has no grade of the grader's (not graded, crashed, timed out).
Row failedRow(const Submission& s, const std::string& status, const std::string& reason);

// Writes the results.json of a submission the grader gave none for (score 0, the reason).
void writeFallbackResults(const std::filesystem::path& results, const Row& row);

// The lab's total points: from the rubric of --lab/--config, else what every graded row agrees on.
double labMaxScore(const std::string& lab, const std::string& config, const std::vector<Row>& rows);

// gradebook.csv: submission, score, max_score, status, reason, folder, then one column per test.
std::string gradebookCsv(std::vector<Row> rows, double lab_max);

// gradebook.md, the summary beside it: how many submissions and of what status, mean, median, min and
// max score (ungraded ones count 0), a histogram of the scores in ten bins of the lab's total, the
// most common failure reasons (numbers in them as #, so one kind of failure is one line) with counts,
// each test's mean, and the submissions that need a look. Every name and reason escaped (mdText).
std::string gradebookMarkdown(std::vector<Row> rows, double lab_max);

}  // namespace dyn::app::batch
