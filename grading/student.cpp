// Whose plant; see student.h.
#include "grading/student.h"

#include <openssl/evp.h>
#include <openssl/hmac.h>

#include <cctype>
#include <cstdlib>

#include "labs/config.h"

namespace dyn {

std::string courseSecret() {
  const char* secret = std::getenv("DYNLAB_COURSE_SECRET");
  return secret ? secret : "";
}

std::string studentKey(const std::string& secret, const std::string& id) {
  unsigned char mac[EVP_MAX_MD_SIZE];
  unsigned int n = 0;
  if (!HMAC(EVP_sha256(), secret.data(), int(secret.size()), reinterpret_cast<const unsigned char*>(id.data()), id.size(),
            mac, &n) || n < 8)
    throw std::runtime_error("HMAC-SHA256 failed (OpenSSL)");
  static const char* hex = "0123456789abcdef";
  std::string key;
  for (unsigned i = 0; i < 8; ++i) {
    key += hex[mac[i] >> 4];
    key += hex[mac[i] & 15];
  }
  return key;
}

std::string studentIdProblem(const std::string& id) {
  if (id.empty() || id.size() > 80) return "expected a student ID of 1–80 bytes, got " + std::to_string(id.size());
  for (unsigned char c : id)
    if (c >= 0x80 || !(std::isalnum(c) || c == '.' || c == '_' || c == '@' || c == '+' || c == '-'))
      return "expected a student ID of ASCII letters, digits and . _ @ + -, got \"" + id + "\"";
  return {};
}

PlantChoice studentPlant(const std::string& id, const std::string& option, const std::string& who) {
  PlantChoice c;
  if (id.empty()) return c;
  if (const std::string problem = studentIdProblem(id); !problem.empty()) throw InputError(who, option, problem);
  c.student = id;
  const std::string secret = courseSecret();
  const char* key = std::getenv("DYNLAB_STUDENT_KEY");
  if (!secret.empty()) {
    c.key = studentKey(secret, id);
  } else if (key && *key) {
    c.key = key;
    if (!isPlantKey(c.key))
      throw InputError("DYNLAB_STUDENT_KEY", option, "expected the 16 hex digits (0-9, a-f) of the key on your handout, got \"" +
                                                         c.key + "\"");
  } else {
    throw InputError(who, option,
                     "expected DYNLAB_STUDENT_KEY (the key on your handout) or, for course staff, DYNLAB_COURSE_SECRET "
                     "to be set: a student's plant is drawn from their key");
  }
  return c;
}

std::string gradescopeStudent(const std::string& metadata_file) {
  const json meta = loadJsonFile(metadata_file, 4u << 20);
  const JsonView user = JsonView(meta, metadata_file)["users"].at(0);
  std::string id;
  if (user.has("sid") && user["sid"].raw().is_string()) id = user["sid"].string();
  const JsonView which = id.empty() ? user["email"] : user["sid"];
  if (id.empty()) id = which.string();
  if (const std::string problem = studentIdProblem(id); !problem.empty()) which.fail(problem);
  return id;
}

}  // namespace dyn
