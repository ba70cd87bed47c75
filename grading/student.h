// Whose plant: a student's ID and key, for a lab's variants (labs/variants.h).
//   key = the first 16 hex digits of HMAC-SHA256(course secret, student ID)
// Staff hold the course secret (DYNLAB_COURSE_SECRET, and in the autograder zip); each student is
// given their own key (printed on their handout) and sets DYNLAB_STUDENT_KEY to tune on their plant.
// The key is a keyed hash, so a student who knows theirs cannot compute a classmate's.
#pragma once
#include <string>

#include "labs/variants.h"

namespace dyn {

// DYNLAB_COURSE_SECRET ("" when unset): the staff's secret every student's key is made with.
std::string courseSecret();

// The first 16 hex digits of HMAC-SHA256(secret, id).
std::string studentKey(const std::string& secret, const std::string& id);

// An ID as dynlab accepts it: 1–80 bytes of ASCII letters, digits and . _ @ + - (a roster's ID, a
// Gradescope student ID or an e-mail address); else why not ("" when fine).
std::string studentIdProblem(const std::string& id);

// The plant of student `id` (option: the option or argument that named it, for the message): the key
// from DYNLAB_COURSE_SECRET if set, else DYNLAB_STUDENT_KEY (16 hex digits), else InputError naming
// `who` (the command line, Python) and the option, and both variables. An empty id is the nominal plant.
PlantChoice studentPlant(const std::string& id, const std::string& option = "--student", const std::string& who = "<command line>");

// The submitter's ID in Gradescope's submission_metadata.json: the first user's "sid" (their Student
// ID), else their "email" (a group is graded on its first member's plant). Throws InputError naming
// the file and the JSON path.
std::string gradescopeStudent(const std::string& metadata_file);

}  // namespace dyn
