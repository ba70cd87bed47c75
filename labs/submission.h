// Gains files and submissions: {"lab": "...", "gains": {...}, <declared options>}. Data only;
// nothing in it is executed. Each lab's JSON declares its gains (value, min, max, unit, doc) and
// the submission options it accepts ("submission_options": {"force_law": {"target":
// "/controller/force_law", "choices": [...]}}); this file applies a submission onto a config,
// validating every value, and derives the submission's JSON Schema from the same declarations.
#pragma once
#include <set>

#include "labs/config.h"

namespace dyn {

// Returns the config with the submission's gains and options applied. strict (grading):
// every declared gain must be present and "lab" must name this lab. Throws InputError naming the
// submission file and JSON path.
json applySubmission(const json& config, const JsonView& submission, const std::string& lab, bool strict);

// A submission's free-text "answers" (the handout's written questions, carried to the TA; never
// graded, never part of the noise seed): an object of at most kMaxAnswers entries, each key a
// short name (letters, digits, _ - .; at most 40 bytes), each value a string of at most
// kMaxAnswerBytes bytes. Returns {} when there are none; throws InputError naming the path.
constexpr std::size_t kMaxAnswers = 20, kMaxAnswerBytes = 4000;
json submissionAnswers(const JsonView& submission);

// Validates a config's "submission_options" (an object of {"target": JSON pointer to a string
// value of the config, "choices": [strings], "doc": string, "reads": {choice: [gains]}}); buildLab
// calls it for every lab. "reads" names the gains that depend on the option: a gain listed under
// some choice is read only under the choices that list it; a gain listed nowhere, under every one.
void checkSubmissionOptions(const JsonView& config);

// The gains the law a config selects reads (its options' "reads"; every gain when none says).
std::set<std::string> gainsRead(const json& config);

// JSON Schema (draft 2020-12) of a submission for this lab.
json submissionSchema(const json& config, const std::string& lab);

}  // namespace dyn
