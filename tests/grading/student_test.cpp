// Whose plant (grading/student.h) and a grade on it: the key is HMAC-SHA256 (RFC 4231's vector), IDs
// are refused outside their alphabet, Gradescope's metadata gives the Student ID or else the e-mail,
// and two students with the same gains are graded on two plants — each the same every time, each
// named in results.json with its values — while the nominal grade is what it was without one.
#include <doctest/doctest.h>
#include <unistd.h>

#include <filesystem>
#include <functional>
#include <map>
#include <vector>
#include <fstream>
#include <nlohmann/json.hpp>

#include "grading/grade.h"
#include "grading/student.h"

namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using namespace dyn;

const fs::path kTmp = fs::path(DYNLAB_TEST_TMP) / ("student_" + std::to_string(::getpid()));

fs::path write(const std::string& name, const std::string& text) {
  fs::create_directories(kTmp);
  std::ofstream(kTmp / name) << text;
  return kTmp / name;
}

// The instructor-free default gains of the five-bar, task inverse dynamics at modest gains.
const std::string kSubmission =
    R"({"lab": "fivebar", "kind": "task_inverse_dynamics", "gains": {"kp": 2000, "kd": 40, "omega_n": 30, "zeta": 0.7}})";

json graded(const PlantChoice& plant) {
  GradeOptions o;
  o.plant = plant;
  const GradeOutcome g = gradeSubmission(write("s.json", kSubmission).string(), o);
  REQUIRE_MESSAGE(!g.input_error, g.error);
  REQUIRE_MESSAGE(!g.internal_error, g.error);
  json r = g.results;
  r.erase("execution_time");
  return r;
}

std::string refusal(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return {};
}

}  // namespace

TEST_CASE("a student's key is the head of HMAC-SHA256(course secret, ID)") {
  // RFC 4231, test case 2: key "Jefe", data "what do ya want for nothing?".
  CHECK(studentKey("Jefe", "what do ya want for nothing?") == "5bdcc146bf60754e");
  CHECK(isPlantKey(studentKey("secret", "alice")));
  CHECK(studentKey("secret", "alice") != studentKey("secret", "bob"));
  CHECK(studentKey("secret", "alice") != studentKey("secret2", "alice"));
}

TEST_CASE("student IDs: a roster's, Gradescope's or an e-mail; nothing else") {
  for (const std::string ok : {"alice", "s1234567", "a.b-c_d+e@uni.example"}) CHECK(studentIdProblem(ok).empty());
  for (const std::string& bad : std::vector<std::string>{"", "a b", "al\x1b[2Jice", "ali/ce", "élise", std::string(81, 'a'), std::string("a\0b", 3)}) {
    CAPTURE(bad);
    CHECK(!studentIdProblem(bad).empty());
  }
}

TEST_CASE("the key comes from the course secret, else the student's own key, else a one-line refusal") {
  ::unsetenv("DYNLAB_COURSE_SECRET");
  ::unsetenv("DYNLAB_STUDENT_KEY");
  CHECK(studentPlant("").nominal());
  CHECK(refusal([] { studentPlant("alice"); }).find("<command line>: --student: expected DYNLAB_STUDENT_KEY") == 0);
  ::setenv("DYNLAB_STUDENT_KEY", "XYZ", 1);
  CHECK(refusal([] { studentPlant("alice"); }).find("DYNLAB_STUDENT_KEY: --student: expected the 16 hex digits") == 0);
  ::setenv("DYNLAB_STUDENT_KEY", studentKey("s3cret", "alice").c_str(), 1);
  const PlantChoice own = studentPlant("alice");
  ::setenv("DYNLAB_COURSE_SECRET", "s3cret", 1);
  const PlantChoice staff = studentPlant("alice");
  CHECK(own.key == staff.key);  // the key on the handout draws the plant the grader draws
  CHECK(refusal([] { studentPlant("a b", "student", "<python>"); }).find("<python>: student: expected a student ID") == 0);
  ::unsetenv("DYNLAB_COURSE_SECRET");
  ::unsetenv("DYNLAB_STUDENT_KEY");
}

TEST_CASE("Gradescope's submitter: the Student ID, else the e-mail; a bad file named") {
  CHECK(gradescopeStudent(write("m1.json", R"({"users": [{"name": "A", "sid": "s123", "email": "a@x.org"}]})").string()) == "s123");
  CHECK(gradescopeStudent(write("m2.json", R"({"users": [{"name": "A", "sid": "", "email": "a@x.org"}]})").string()) == "a@x.org");
  CHECK(gradescopeStudent(write("m3.json", R"({"users": [{"email": "a@x.org"}, {"email": "b@x.org"}]})").string()) == "a@x.org");
  const std::string none = write("m4.json", R"({"users": []})").string();
  CHECK(refusal([&] { gradescopeStudent(none); }).find("m4.json: /users") != std::string::npos);
  const std::string spaced = write("m5.json", R"({"users": [{"sid": "s 1"}]})").string();
  CHECK(refusal([&] { gradescopeStudent(spaced); }).find("m5.json: /users/0/sid: expected a student ID") != std::string::npos);
}

TEST_CASE("two students, the same gains, two plants: each graded the same every time, each named with its values") {
  const json nominal = graded({});
  CHECK(!nominal["extra_data"].contains("student"));
  std::map<std::string, json> by;
  for (const std::string id : {"alice", "bob", "carol", "dave"}) by[id] = graded({id, studentKey("course", id)});
  CHECK(graded({"alice", studentKey("course", "alice")}) == by["alice"]);
  int differ = 0;
  for (const auto& [id, r] : by) {
    CAPTURE(id);
    CHECK(r["extra_data"]["student"] == id);
    REQUIRE(r["extra_data"]["plant"].contains("/plant/payloads/0/mass"));
    CHECK(r["output"].get<std::string>().find("Graded on the plant of student " + id) != std::string::npos);
    differ += r["score"] != by["alice"]["score"];
    // The plant graded is in the fingerprint: a replay on another plant is told apart.
    const bool same_plant = r["extra_data"]["plant"] == by["alice"]["extra_data"]["plant"];
    CHECK((r["extra_data"]["fingerprint"]["lab_config_hash"] == by["alice"]["extra_data"]["fingerprint"]["lab_config_hash"]) == same_plant);
  }
  CHECK(differ >= 1);
}
