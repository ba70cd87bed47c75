// Measured numbers in a lab's README, each marked with where it comes from and checked against a run,
// so a README cannot go stale unnoticed:
//   max |Δq| 1.9e-3<!-- measured: /agreement/max_dq --> rad
// The marker (an HTML comment: invisible where the README is shown) follows the number at once; its
// JSON pointer names a number of the summary.json that `dynlab run LAB` writes (the default gains,
// both engines, the whole run). A number agrees when the run's value rounds to it at the digits
// written (1.9e-3 stands for [1.85e-3, 1.95e-3]). check-lab checks every marked number.
#pragma once
#include <string>
#include <vector>

#include "labs/config.h"

namespace dyn {

struct ReadmeNumber {
  int line = 0;         // 1-based
  std::string written;  // as the README has it: "1.9e-3"
  std::string pointer;  // into summary.json: "/agreement/max_dq"
};

// Every marked number of a README's text, in order.
std::vector<ReadmeNumber> readmeNumbers(const std::string& text);

// Whether `measured` rounds to `written` at the digits written.
bool agreesAsWritten(const std::string& written, double measured);

// One line per marked number that names no number of the summary or disagrees with it, e.g.
// "README.md line 35: 3.5e-4 is written, the run measures 0.00194 (/agreement/max_dq)"; empty: all agree.
std::vector<std::string> readmeNumberProblems(const std::string& text, const json& summary, const std::string& file);

}  // namespace dyn
