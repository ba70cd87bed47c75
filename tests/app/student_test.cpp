// A plant per student through the binary: `dynlab handout fivebar --student alice` and `bob` show
// two plants and each their key; the key on alice's handout, set as DYNLAB_STUDENT_KEY, runs and
// grades the plant the staff's course secret grades; `grade --student` differs between students;
// the batch takes each student from the folder's name or a roster and refuses to start without the
// course secret; run_autograder takes the submitter from Gradescope's metadata. Without a key, or
// with a bad ID, one line and exit 2.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>
#include <regex>

#include "tests/app/cli_run.h"

using namespace dyn::test::cli;
using json = nlohmann::json;

namespace {

const std::string kSecret = "course-secret-for-tests";
const std::string kGains =
    R"({"lab": "fivebar", "kind": "task_inverse_dynamics", "gains": {"kp": 2000, "kd": 40, "omega_n": 30, "zeta": 0.7}})";

ProcessOptions staff() { return withEnv({{"DYNLAB_COURSE_SECRET", kSecret}}); }

// The plant table's rows and the key of a student's handout.
std::string handoutOf(const TempDir& dir, const std::string& student, const ProcessOptions& env) {
  const Result r = dynlab(dir, {"handout", "fivebar", "--student", student, "--format", "md", "--out", "h-" + student}, env);
  REQUIRE_MESSAGE(r.code == 0, r.err);
  return readFile(dir / ("h-" + student) / "handout.md");
}

std::string keyOn(const std::string& handout) {
  std::smatch m;
  REQUIRE(std::regex_search(handout, m, std::regex("Your key is `([0-9a-f]{16})`")));
  return m[1];
}

std::string plantRows(const std::string& handout) {
  const auto from = handout.find("## Your plant"), to = handout.find("## Your gains");
  REQUIRE(from != std::string::npos);
  REQUIRE(to != std::string::npos);
  return handout.substr(from, to - from);
}

json gradeAs(const TempDir& dir, const std::string& student, const ProcessOptions& env, const std::string& out) {
  const Result r = dynlab(dir, {"grade", "s.json", "--student", student, "--no-plots", "--out", out}, env);
  REQUIRE_MESSAGE(r.code == 0, r.err);
  return json::parse(readFile(dir / out / "results.json"));
}

}  // namespace

TEST_CASE("handouts of two students show two plants, each with a key that reproduces the grader's plant") {
  TempDir dir("student_handout");
  const std::string alice = handoutOf(dir, "alice", staff()), bob = handoutOf(dir, "bob", staff());
  CHECK(plantRows(alice).find("student `alice`") != std::string::npos);
  CHECK(plantRows(alice) != plantRows(bob));
  CHECK(keyOn(alice) != keyOn(bob));
  // Alice, at home with her key (no course secret), sees and is graded on the same plant.
  const ProcessOptions home = withEnv({{"DYNLAB_STUDENT_KEY", keyOn(alice)}});
  CHECK(handoutOf(dir, "alice", home) == alice);
  writeFile(dir / "s.json", kGains);
  const json by_staff = gradeAs(dir, "alice", staff(), "g1"), at_home = gradeAs(dir, "alice", home, "g2");
  CHECK(by_staff["score"] == at_home["score"]);
  CHECK(by_staff["extra_data"]["plant"] == at_home["extra_data"]["plant"]);
  // The nominal handout lists the ranges, not anyone's values or key.
  const Result nominal = dynlab(dir, {"handout", "fivebar", "--format", "md", "--out", "h"});
  REQUIRE(nominal.code == 0);
  const std::string text = readFile(dir / "h" / "handout.md");
  CHECK(text.find("## Your plant") != std::string::npos);
  CHECK(text.find("Your key is") == std::string::npos);
}

TEST_CASE("grade and run --student: the same gains score differently on two students' plants") {
  TempDir dir("student_grade");
  writeFile(dir / "s.json", kGains);
  std::map<std::string, json> by;
  for (const std::string id : {"alice", "bob", "carol"}) by[id] = gradeAs(dir, id, staff(), "g-" + id);
  CHECK((by["alice"]["score"] != by["bob"]["score"] || by["alice"]["score"] != by["carol"]["score"]));
  CHECK(by["alice"]["extra_data"]["student"] == "alice");
  // The replay line names the student, and replays.
  const Result again = dynlab(dir, {"grade", "--replay", "g-alice/results.json", "s.json", "--student", "alice"}, staff());
  CHECK_MESSAGE(again.code == 0, again.err);
  // run --student: the trace of alice's plant is not bob's.
  const Result ra = dynlab(dir, {"run", "fivebar", "--engine", "hand", "--duration", "0.3", "--student", "alice", "--out", "ra"}, staff());
  const Result rb = dynlab(dir, {"run", "fivebar", "--engine", "hand", "--duration", "0.3", "--student", "bob", "--out", "rb"}, staff());
  REQUIRE_MESSAGE(ra.code == 0, ra.err);
  REQUIRE_MESSAGE(rb.code == 0, rb.err);
  const json pa = by["alice"]["extra_data"]["plant"], pb = by["bob"]["extra_data"]["plant"];
  if (pa != pb) CHECK(readFile(dir / "ra" / "trace_hand.csv") != readFile(dir / "rb" / "trace_hand.csv"));
}

TEST_CASE("no key, a bad key or a bad ID: one line, exit 2, nothing graded") {
  TempDir dir("student_refused");
  writeFile(dir / "s.json", kGains);
  const Result none = dynlab(dir, {"grade", "s.json", "--student", "alice", "--out", "g"});
  CHECK(none.code == 2);
  CHECK(none.err == "error: <command line>: --student: expected DYNLAB_STUDENT_KEY (the key on your handout) or, for course "
                    "staff, DYNLAB_COURSE_SECRET to be set: a student's plant is drawn from their key\n");
  CHECK(!fs::exists(dir / "g" / "results.json"));
  const Result bad_key = dynlab(dir, {"run", "fivebar", "--student", "alice"}, withEnv({{"DYNLAB_STUDENT_KEY", "0123"}}));
  CHECK(bad_key.code == 2);
  CHECK(bad_key.err.find("DYNLAB_STUDENT_KEY: --student: expected the 16 hex digits") != std::string::npos);
  const Result bad_id = dynlab(dir, {"handout", "fivebar", "--student", "al\x1b[31mice"}, staff());
  CHECK(bad_id.code == 2);
  CHECK(bad_id.err.find("--student: expected a student ID of ASCII letters") != std::string::npos);
  CHECK(bad_id.err.find('\x1b') == std::string::npos);
  CHECK(std::count(bad_id.err.begin(), bad_id.err.end(), '\n') == 1);
}

TEST_CASE("the batch grades each student on their plant: the folder's name, or the roster's ID") {
  TempDir dir("student_batch");
  fs::create_directories(dir / "subs" / "alice");
  fs::create_directories(dir / "subs" / "bob");
  writeFile(dir / "subs" / "alice" / "submission.json", kGains);
  writeFile(dir / "subs" / "bob" / "submission.json", kGains);
  writeFile(dir / "subs" / "carol.json", kGains);
  // Without the course secret the batch refuses before it grades anything.
  const Result refused = dynlab(dir, {"grade", "--batch", "subs", "--no-plots", "--out", "b0"});
  CHECK(refused.code == 2);
  CHECK(refused.err.find("--batch: expected DYNLAB_COURSE_SECRET to be set") != std::string::npos);
  const Result r = dynlab(dir, {"grade", "--batch", "subs", "--no-plots", "--out", "b"}, staff());
  REQUIRE_MESSAGE(r.code == 0, r.err);
  writeFile(dir / "s.json", kGains);
  for (const auto& [id, folder] : std::map<std::string, std::string>{{"alice", "alice"}, {"bob", "bob"}, {"carol", "carol"}}) {
    const json one = json::parse(readFile(dir / "b" / folder / "results.json"));
    CHECK(one["extra_data"]["student"] == id);
    CHECK(one["score"] == gradeAs(dir, id, staff(), "one-" + id)["score"]);
  }
  // A roster: names → IDs; a submission not in it is not graded as anyone.
  writeFile(dir / "roster.csv", "submission,student\nalice,s001\nbob,s002\n");
  const Result rr = dynlab(dir, {"grade", "--batch", "subs", "--roster", "roster.csv", "--no-plots", "--out", "br"}, staff());
  CHECK(rr.code != 3);
  CHECK(json::parse(readFile(dir / "br" / "alice" / "results.json"))["extra_data"]["student"] == "s001");
  const std::string gradebook = readFile(dir / "br" / "gradebook.csv");
  CHECK(gradebook.find("not in the roster") != std::string::npos);
  // A roster line that is not NAME,ID is named.
  writeFile(dir / "bad.csv", "alice,s 1\n");
  const Result bad = dynlab(dir, {"grade", "--batch", "subs", "--roster", "bad.csv", "--out", "bb"}, staff());
  CHECK(bad.code == 2);
  CHECK(bad.err.find("bad.csv: line 1: expected a student ID") != std::string::npos);
}

TEST_CASE("Gradescope: grade --student-from the submission's metadata, as run_autograder calls it") {
  TempDir dir("student_gradescope");
  writeFile(dir / "s.json", kGains);
  writeFile(dir / "meta.json", R"({"id": 1, "users": [{"name": "Bob", "email": "bob@uni.example", "sid": ""}]})");
  const Result r = dynlab(dir, {"grade", "s.json", "--lab", "fivebar", "--student-from", "meta.json", "--no-plots", "--out", "g"}, staff());
  REQUIRE_MESSAGE(r.code == 0, r.err);
  const json g = json::parse(readFile(dir / "g" / "results.json"));
  CHECK(g["extra_data"]["student"] == "bob@uni.example");
  CHECK(g["score"] == gradeAs(dir, "bob@uni.example", staff(), "g2")["score"]);
}

TEST_CASE("the autograder zip carries the course secret, and run_autograder grades the submitter's plant") {
  TempDir dir("student_autograder");
  // Without the secret there is no zip: its students' plants could not be drawn.
  const Result refused = dynlab(dir, {"autograder", "fivebar", "--out", "a0.zip"});
  CHECK(refused.code != 0);
  CHECK(refused.err.find("set DYNLAB_COURSE_SECRET") != std::string::npos);
  CHECK(!fs::exists(dir / "a0.zip"));
  const Result made = dynlab(dir, {"autograder", "fivebar", "--out", "a.zip"}, staff());
  REQUIRE_MESSAGE(made.code == 0, made.err);
  const Result unzipped = run(dir, {"unzip", "-q", "a.zip", "run_autograder", "course_secret", "-d", "z"});
  REQUIRE_MESSAGE(unzipped.code == 0, unzipped.err);
  CHECK(readFile(dir / "z" / "course_secret") == kSecret);
  fs::create_directories(dir / "upload");
  writeFile(dir / "upload" / "submission.json", kGains);
  writeFile(dir / "meta.json", R"({"users": [{"name": "Alice", "email": "alice@uni.example", "sid": "s0042"}]})");
  // Gradescope's run: no secret in the environment, only the zip's file.
  const Result graded = run(dir, {"bash", "z/run_autograder"},
                            withEnv({{"DYNLAB_BIN", DYNLAB_BIN}, {"DYNLAB_SUBMISSION_DIR", (dir / "upload").string()},
                                     {"DYNLAB_RESULTS_DIR", (dir / "results").string()},
                                     {"DYNLAB_SECRET_FILE", (dir / "z" / "course_secret").string()},
                                     {"DYNLAB_METADATA", (dir / "meta.json").string()}}));
  REQUIRE_MESSAGE(graded.code == 0, graded.err);
  const json results = json::parse(readFile(dir / "results" / "results.json"));
  CHECK(results["extra_data"]["student"] == "s0042");
  writeFile(dir / "s.json", kGains);
  CHECK(results["score"] == gradeAs(dir, "s0042", staff(), "g")["score"]);
}
