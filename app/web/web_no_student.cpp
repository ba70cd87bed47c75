// The page has no per-student plants (grading/student.cpp needs OpenSSL's HMAC, native only): the one
// call the handout's code names (app/cli/course/handout.cpp), for the nominal plant it always asks.
#include "grading/student.h"
#include "labs/config.h"

namespace dyn {

PlantChoice studentPlant(const std::string& id, const std::string& option, const std::string& who) {
  if (id.empty()) return {};
  throw InputError(who, option, "the nominal plant: a student's own plant is drawn by the native dynlab, not in the page");
}

}  // namespace dyn
