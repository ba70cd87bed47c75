// A README's measured numbers (app/cli/authoring/readme_numbers.h): each marked number is found on its line with its
// pointer, agrees when the run's value rounds to it at the digits written (and only then), and one
// that disagrees or points at nothing is named with its line, what is written and what the run
// measures. The five-bar's README once said 3.5e-4 rad where the run measured 1.94e-3.
#include <doctest/doctest.h>

#include "app/cli/authoring/readme_numbers.h"

using namespace dyn;

TEST_CASE("a marked number agrees when the run rounds to it at the digits written") {
  CHECK(agreesAsWritten("1.9e-3", 0.0019419960508865186));
  CHECK(agreesAsWritten("1.9e-3", 0.00185));
  CHECK_FALSE(agreesAsWritten("1.9e-3", 0.00184));
  CHECK_FALSE(agreesAsWritten("3.5e-4", 0.0019419960508865186));
  CHECK(agreesAsWritten("0.13", 0.1329149466754549));
  CHECK_FALSE(agreesAsWritten("0.133", 0.1329149466754549 + 0.0006));
  CHECK(agreesAsWritten("27", 27.4));
  CHECK_FALSE(agreesAsWritten("27", 27.6));
  CHECK(agreesAsWritten("-0.5", -0.54));
  CHECK_FALSE(agreesAsWritten("1", NAN));
}

TEST_CASE("marked numbers are found with their lines; a stale or dangling one is named") {
  const std::string text = "# lab\n\nmax |dq| 1.9e-3<!-- measured: /agreement/max_dq --> rad, and\n"
                           "force 6<!-- measured: /agreement/max_df --> mN, unmarked 3.5e-4 rad,\n"
                           "gone 2<!-- measured: /agreement/nothing -->\n";
  const auto numbers = readmeNumbers(text);
  REQUIRE(numbers.size() == 3);
  CHECK(numbers[0].line == 3);
  CHECK(numbers[0].written == "1.9e-3");
  CHECK(numbers[0].pointer == "/agreement/max_dq");
  CHECK(numbers[1].line == 4);
  CHECK(numbers[2].line == 5);
  const json summary = {{"agreement", {{"max_dq", 0.0019419960508865186}, {"max_df", 0.1329149466754549}}}};
  const auto problems = readmeNumberProblems(text, summary, "README.md");
  REQUIRE(problems.size() == 2);
  CHECK(problems[0] == "README.md line 4: 6 is written, the run measures 0.133 (/agreement/max_df)");
  CHECK(problems[1] == "README.md line 5: 2 is marked as measured at \"/agreement/nothing\", which is not a number of "
                       "`dynlab run`'s summary.json");
  CHECK(readmeNumberProblems("no marks here 1.9e-3 rad", summary, "README.md").empty());
}
