// The Gradescope autograder zip; see autograder.h.
// Entries are collected in memory, sorted by name and written with libzip with a fixed DOS time
// (1980-01-01 00:00) and Unix modes, so the same tree gives the same bytes.
#include "app/cli/course/autograder.h"

#include <sys/stat.h>
#include <zip.h>

#include <algorithm>
#include <cstdlib>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <vector>

#include "grading/student.h"

namespace dyn::app {
namespace {

namespace fs = std::filesystem;

// Where Gradescope unpacks the zip; the source tree lands in its source/ folder.
constexpr const char* kRoot = "/autograder/source/source";
// What of the dynlab tree goes into the bundle (tests/ too: the top CMakeLists adds it; docs/: the README links the notes).
constexpr const char* kTopFiles[] = {"CMakeLists.txt", "README.md"};
constexpr const char* kTopDirs[] = {"app", "assets", "docs", "grading", "labs", "physics", "render", "scripts", "tests"};

struct Entry {
  std::string name;  // path inside the zip, '/'-separated
  std::string data;
  unsigned mode;     // Unix permission bits
};

[[noreturn]] void fail(const std::string& path, const std::string& why) {
  throw std::runtime_error("autograder " + path + ": " + why);
}

std::string readFile(const fs::path& p, const std::string& zip_path) {
  std::ifstream in(p, std::ios::binary);
  if (!in) fail(zip_path, "cannot read " + p.string());
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string replaceAll(std::string s, const std::string& from, const std::string& to) {
  for (size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size())) s.replace(at, from.size(), to);
  return s;
}

// Build output, run output, VCS data, staging folders and temp files stay out of the bundle, and so
// do the labs' instructor/ folders (full-credit examples: course staff only; grading never reads them).
bool skipped(const fs::directory_entry& e) {
  const std::string name = e.path().filename().string();
  if (e.is_directory()) return name.rfind("build", 0) == 0 || name == "out" || name[0] == '.' || name == "instructor";
  return name.size() > 4 && name.compare(name.size() - 4, 4, ".tmp") == 0;
}

// The listed files and folders of the dynlab tree, under source/; executables keep 0755.
void addSourceTree(const fs::path& src, const std::string& zip_path, std::vector<Entry>& out) {
  if (!fs::is_regular_file(src / "CMakeLists.txt")) fail(zip_path, src.string() + " is not a dynlab source tree (no CMakeLists.txt)");
  const auto add = [&](const fs::path& file) {
    const auto perms = fs::status(file).permissions();
    const bool exec = (perms & fs::perms::owner_exec) != fs::perms::none;
    out.push_back({"source/" + fs::relative(file, src).generic_string(), readFile(file, zip_path), exec ? 0755u : 0644u});
  };
  for (const char* f : kTopFiles)
    if (fs::is_regular_file(src / f)) add(src / f);
  for (const char* d : kTopDirs) {
    if (!fs::is_directory(src / d)) continue;
    for (auto it = fs::recursive_directory_iterator(src / d); it != fs::recursive_directory_iterator(); ++it) {
      if (skipped(*it)) {
        if (it->is_directory()) it.disable_recursion_pending();
        continue;
      }
      if (it->is_regular_file() && !it->is_symlink()) add(it->path());
    }
  }
}

// A lab folder outside the tree, under source/labs/<lab>/ (what addSourceTree leaves out, left out).
void addLabFolder(const fs::path& folder, const std::string& lab, const std::string& zip_path, std::vector<Entry>& out) {
  for (auto it = fs::recursive_directory_iterator(folder); it != fs::recursive_directory_iterator(); ++it) {
    if (skipped(*it)) {
      if (it->is_directory()) it.disable_recursion_pending();
      continue;
    }
    if (it->is_regular_file() && !it->is_symlink())
      out.push_back({"source/labs/" + lab + "/" + fs::relative(it->path(), folder).generic_string(), readFile(it->path(), zip_path), 0644u});
  }
}

// setup.sh: once, as root, when Gradescope builds the image (Ubuntu 22.04): only what grading the lab
// needs, chosen from what the image's apt offers (scripts/autograder-packages), and a dynlab built
// without the rest. model_files: the lab reads an MJCF/URDF file (MuJoCo's parser is required).
std::string setupScript(bool model_files) {
  return replaceAll(replaceAll(R"SH(#!/usr/bin/env bash
# Gradescope runs this once, as root, when it builds the autograder image (Ubuntu 22.04; see
# README.md): the packages grading needs, chosen by source/scripts/autograder-packages from what
# this image offers, then dynlab itself (Release), without what grading does not use.
set -euo pipefail
src=@ROOT@
export DEBIAN_FRONTEND=noninteractive

# Packages: a package the image lacks is named in one line, and the build stops there.
apt-get update -qq
choice="$(bash "$src/scripts/autograder-packages" @MODEL_FILES@)" || exit 1
read -ra packages <<<"$(printf '%s\n' "$choice" | sed -n 's/^packages: //p')"
read -ra options <<<"$(printf '%s\n' "$choice" | sed -n 's/^cmake: //p')"
echo "setup.sh: installing ${packages[*]}"
apt-get install -y -qq --no-install-recommends "${packages[@]}"
pkg-config --exists bullet-float64 || {
  echo "setup.sh: this image's libbullet-dev has no double-precision build (pkg-config bullet-float64), which dynlab needs: see docs/teaching.md, \"Which base image\"" >&2
  exit 1
}

# dynlab needs CMake >= 3.25; Ubuntu 22.04 ships 3.22, so take a newer one from PyPI when needed.
have="$(cmake --version 2>/dev/null | head -n1 | awk '{print $3}')"
if ! printf '3.25\n%s\n' "$have" | sort -V -C; then
  apt-get install -y -qq --no-install-recommends python3-pip
  python3 -m pip install --no-cache-dir 'cmake>=3.25'
  hash -r
fi

# Build only the dynlab binary, with the options chosen above (tests, video and, for a lab without a
# model file, MuJoCo left out).
echo "setup.sh: cmake options ${options[*]}"
cmake -S "$src" -B "$src/build" -DCMAKE_BUILD_TYPE=Release "${options[@]}"
cmake --build "$src/build" --target dynlab -j2
"$src/build/app/dynlab" list
)SH",
                               "@MODEL_FILES@", model_files ? "--model-files" : ""),
                    "@ROOT@", kRoot);
}

// run_autograder: per submission; every way out leaves a valid results.json.
std::string runScript(const std::string& lab) {
  return replaceAll(replaceAll(R"SH(#!/usr/bin/env bash
# Gradescope runs this once per submission: grade the student's JSON for the lab @LAB@ with dynlab,
# and always leave a valid /autograder/results/results.json, also when grading itself fails.
# To try it locally, override DYNLAB_BIN, DYNLAB_SUBMISSION_DIR, DYNLAB_RESULTS_DIR, DYNLAB_TIME_LIMIT
# (and DYNLAB_SECRET_FILE, the zip's course_secret, and DYNLAB_METADATA, the submission_metadata.json,
# for a lab with a plant per student).
set -uo pipefail

lab="@LAB@"
dynlab="${DYNLAB_BIN:-@ROOT@/build/app/dynlab}"
submission_dir="${DYNLAB_SUBMISSION_DIR:-/autograder/submission}"
results_dir="${DYNLAB_RESULTS_DIR:-/autograder/results}"
results="$results_dir/results.json"

# The time limit: whole seconds from 1 to 86400, below Gradescope's 10 minutes by default so this
# script still reports. Anything else (0, 10m, -5) is a staff typo: say so, and use the default.
time_limit="${DYNLAB_TIME_LIMIT:-540}"
if ! [[ "$time_limit" =~ ^[0-9]{1,5}$ ]] || ((10#$time_limit < 1 || 10#$time_limit > 86400)); then
  echo "run_autograder: DYNLAB_TIME_LIMIT=\"$time_limit\": expected whole seconds from 1 to 86400; using the default, 540" >&2
  time_limit=540
fi
time_limit=$((10#$time_limit))

# Text as the inside of a JSON string: backslashes and quotes escaped, control characters dropped.
json_text() {
  printf '%s' "$1" | sed -e 's/\\/\\\\/g' -e 's/"/\\"/g' | tr -d '\000-\037\177'
}

# Score 0 with a fixed message ($1 is already JSON-escaped; nothing from the submission goes in).
# Whatever sits at $results (a stale file, a FIFO, a folder) is replaced, never written through.
fail() {
  rm -rf -- "$results" "$results.tmp"
  printf '{"score": 0.0, "output_format": "md", "output": "%s", "tests": []}\n' "$1" > "$results.tmp"
  mv -f -- "$results.tmp" "$results"
  echo "run_autograder: no grade from dynlab; wrote a score-0 results.json"
  exit 0
}

mkdir -p "$results_dir"
rm -rf -- "$results"

[ -x "$dynlab" ] || fail 'The autograder is broken: dynlab was not built when the image was set up. This is not your fault; please tell the course staff.'

# The student's file, by the rule the batch grader shares (dynlab submission-file, docs/teaching.md "Grading"):
# submission.json, else the only *.json uploaded, hidden and editor files aside; a link out of the
# upload, a FIFO or a device is refused unread. The path is printed with a trailing "/" guard so a
# name ending in a newline survives the command substitution.
file="$("$dynlab" submission-file "$submission_dir"; rc=$?; printf '/'; exit $rc)"
select_status=$?
file="${file%/}"
file="${file%$'\n'}"
case $select_status in
  0) ;;
  2) fail "Your submission could not be graded: $(json_text "$file").\n\nUpload one file named \`submission.json\` of the form \`{\\\"lab\\\": \\\"@LAB@\\\", \\\"gains\\\": {...}}\` (see the lab handout for the gain names)." ;;
  *) fail 'The autograder could not look at your submission. This is not your fault; please tell the course staff.' ;;
esac

# Grade within the time limit; dynlab writes results.json (each test's plot inline, for the student
# to see on Gradescope), report.md and plots/ itself. Its own
# time budget (3/4 of the limit, at most 300 s) lets it explain a slow run before it is stopped.
budget=$((time_limit * 3 / 4))
((budget >= 1)) || budget=1
((budget <= 300)) || budget=300
started=$SECONDS
# A lab with a plant per student: the course secret (staff-only, in this zip) and the submitter's ID
# from Gradescope's metadata (dynlab reads it: their Student ID, else their e-mail).
student=()
secret_file="${DYNLAB_SECRET_FILE:-/autograder/source/course_secret}"
if [ -f "$secret_file" ]; then
  DYNLAB_COURSE_SECRET="$(cat -- "$secret_file")"
  export DYNLAB_COURSE_SECRET
  student=(--student-from "${DYNLAB_METADATA:-/autograder/submission_metadata.json}")
fi
timeout --kill-after=10 "$time_limit" "$dynlab" grade "$file" --time-budget "$budget" --lab "$lab" "${student[@]}" --inline-plots --out "$results_dir"
status=$?
elapsed=$((SECONDS - started))
# Its results.json stands only if Gradescope would accept it, checked by dynlab check-results.
problem=""
if [ -e "$results" ] || [ -L "$results" ]; then
  problem="$(timeout 60 "$dynlab" check-results "$results" 2>&1 >/dev/null)" && exit 0
  [ -n "$problem" ] || problem="dynlab check-results stopped without saying why"
  echo "run_autograder: $problem" >&2
fi
# 124: stopped at the time limit; 137 after it: killed when it ignored the stop (before it, a crash).
if ((status == 124 || (status == 137 && elapsed >= time_limit))); then
  fail "Grading took longer than $time_limit seconds and was stopped. Gains that make the simulation stiff or unstable can do this: check them against the limits in the lab handout and resubmit."
fi
[ -z "$problem" ] || fail "The grader wrote a results.json that Gradescope would not accept, so this one replaces it. This is not a judgement of your gains; please tell the course staff.\n\n    $(json_text "$problem")"
fail "The grader stopped (exit status $status) without writing results. This is not a judgement of your gains; please resubmit, and tell the course staff if it happens again."
)SH",
                               "@LAB@", lab),
                    "@ROOT@", kRoot);
}

// README.md for the course staff: upload steps, what students submit, how to try it locally.
std::string readme(const std::string& lab, const nlohmann::json& config) {
  const std::string title = config.value("title", lab);
  // The example: the lab's default gains; the table: each gain's default, bounds, unit and meaning.
  nlohmann::ordered_json example = {{"lab", lab}, {"gains", nlohmann::ordered_json::object()}};
  std::string table = "| gain | default | allowed | unit | meaning |\n|---|---|---|---|---|\n";
  const auto field = [](const nlohmann::json& g, const char* key) { return g.value(key, nlohmann::json()).dump(); };
  if (config.contains("gains") && config["gains"].is_object()) {
    for (const auto& [name, g] : config["gains"].items()) {
      example["gains"][name] = g.value("value", 0.0);
      table += "| `" + name + "` | " + field(g, "value") + " | " + field(g, "min") + " … " + field(g, "max") + " | " +
               g.value("unit", std::string()) + " | " + g.value("doc", std::string()) + " |\n";
    }
  }
  // Optional keys (e.g. which control law the gains are for).
  std::string options;
  if (config.contains("submission_options") && config["submission_options"].is_object())
    for (const auto& [key, o] : config["submission_options"].items())
      options += "* `\"" + key + "\"`: one of " + field(o, "choices") + " (" + o.value("doc", std::string()) + ")\n";
  if (!options.empty()) options = "\nOptional keys besides `lab` and `gains`:\n\n" + options;
  std::string md = R"MD(# dynlab autograder: @TITLE@

This zip is a Gradescope autograder for the dynlab lab `@LAB@`. It holds:

* `setup.sh`: run once when Gradescope builds the image: installs only the packages grading needs
  (chosen by `source/scripts/autograder-packages` from what the image offers) and compiles dynlab
  (Release) into `source/build/`, without the window, video, Python and the tests@NO_MUJOCO@.
* `run_autograder`: run for every submission: finds the student's JSON (a symbolic link out of the
  submission, a FIFO or a device is refused unread), runs
  `dynlab grade FILE --time-budget B --lab @LAB@ --inline-plots --out /autograder/results` (B: 3/4
  of the time limit, at most 300 s, so dynlab explains a slow run itself; each test's feedback is
  HTML with its response plot inline, which Gradescope shows the student), and always leaves a valid
  `results.json` (score 0 with an explanation when the file is missing, grading fails, or what
  dynlab wrote does not pass `dynlab check-results`). Set `DYNLAB_TIME_LIMIT` (whole seconds,
  1–86400; default 540) to change how long dynlab may grade.
* `source/`: the dynlab source tree the grader is built from.

## Setting it up on Gradescope

1. Create a **Programming Assignment** (any name; total points as in the lab's rubric).
2. Under **Configure Autograder**, choose **Zip file upload**, base image **Ubuntu 22.04**, upload
   this zip and press **Update Autograder** (@IMAGE_NOTE@). The image build installs packages and compiles
   dynlab: allow 10–20 minutes, and read the build log if it fails: a package the image lacks is
   named in one line starting `autograder-packages:` or `setup.sh:` (docs/teaching.md, "Which
   base image", says what is known about each).
3. Keep the autograder timeout at 10 minutes or more: `run_autograder` stops dynlab after 540 s
   so that it can still explain a timeout to the student.
4. Press **Test Autograder** and upload the example below as `submission.json`.

## What students work from

The lab handout: `dynlab handout @LAB@` writes `handout.md` and `handout.html` (the mechanism, the
exercise, every gain with its bounds, the submission format, each test and scenario with its
metric, unit and window, how to tune and self-grade). Give it to the students; the feedback's
"see the lab handout" means it. Full-credit examples (`labs/@LAB@/instructor/`) are not in this zip.

## What students submit

One JSON file, best named `submission.json` (if they upload a single JSON file under another
name, that one is graded):

```json
@EXAMPLE@
```

The gains of this lab (all of them are required):

@TABLE@@OPTIONS@
A submission naming another lab, with unknown or missing gains, or with a gain outside its
bounds, gets score 0 and a message saying what to fix; a run that goes unstable is explained in
the feedback, not reported as a crash. `dynlab schema @LAB@` prints the JSON Schema of a submission.

## Trying it locally

Unzip, build dynlab as `setup.sh` does (or use an existing build), then:

```sh
mkdir -p sub res && cp my.json sub/submission.json
DYNLAB_BIN=path/to/dynlab DYNLAB_SUBMISSION_DIR=sub DYNLAB_RESULTS_DIR=res bash run_autograder
path/to/dynlab check-results res/results.json   # the check run_autograder makes
```
)MD";
  // Which image works: a lab without a model file needs no MuJoCo; one with a model file does.
  const bool model_files = config.contains("model_file");
  md = replaceAll(md, "@NO_MUJOCO@", model_files ? "" : " (and without MuJoCo: this lab reads no model file)");
  md = replaceAll(md, "@IMAGE_NOTE@",
                  model_files ? "this lab reads a model file, so the image must offer\n   `libmujoco-dev`; if setup.sh stops "
                                "with \"this image has no libmujoco-dev\", this lab\n   cannot be graded on that image"
                              : "this lab reads no model file: it needs no MuJoCo");
  md = replaceAll(md, "@TITLE@", title);
  md = replaceAll(md, "@LAB@", lab);
  md = replaceAll(md, "@EXAMPLE@", example.dump(2));
  md = replaceAll(md, "@OPTIONS@", options);
  return replaceAll(md, "@TABLE@", table);
}

// Writes the entries in name order with fixed times and Unix modes (to zip_path + ".tmp", renamed at the end).
void writeZip(std::vector<Entry> entries, const std::string& zip_path) {
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.name < b.name; });
  const std::string tmp = zip_path + ".tmp";
  if (std::FILE* f = std::fopen(tmp.c_str(), "wb")) {
    std::fclose(f);
  } else {
    fail(zip_path, "cannot write " + tmp + ": " + std::strerror(errno));
  }
  int err = 0;
  zip_t* za = zip_open(tmp.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &err);
  if (!za) {
    std::remove(tmp.c_str());
    fail(zip_path, "cannot create the zip (libzip error " + std::to_string(err) + ")");
  }
  const auto abandon = [&](const std::string& why) {
    const std::string detail = zip_strerror(za);
    zip_discard(za);
    std::remove(tmp.c_str());
    fail(zip_path, why + ": " + detail);
  };
  constexpr zip_uint16_t kDosTime = 0, kDosDate = (0 << 9) | (1 << 5) | 1;  // 1980-01-01 00:00
  for (const Entry& e : entries) {
    // The buffers stay alive (in `entries`) until zip_close reads them.
    zip_source_t* s = zip_source_buffer(za, e.data.data(), e.data.size(), 0);
    if (!s) abandon("cannot add " + e.name);
    const zip_int64_t i = zip_file_add(za, e.name.c_str(), s, ZIP_FL_ENC_UTF_8);
    if (i < 0) {
      zip_source_free(s);
      abandon("cannot add " + e.name);
    }
    const auto idx = static_cast<zip_uint64_t>(i);
    if (zip_set_file_compression(za, idx, ZIP_CM_DEFLATE, 9) < 0 || zip_file_set_dostime(za, idx, kDosTime, kDosDate, 0) < 0 ||
        zip_file_set_external_attributes(za, idx, 0, ZIP_OPSYS_UNIX, (S_IFREG | e.mode) << 16) < 0)
      abandon("cannot set the attributes of " + e.name);
  }
  if (zip_close(za) < 0) abandon("cannot write the zip");
  std::error_code ec;
  fs::rename(tmp, zip_path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    fail(zip_path, "cannot rename " + tmp + ": " + ec.message());
  }
}

}  // namespace

void writeAutograder(const std::string& lab, const std::string& source_dir, const std::string& zip_path, const std::string& lab_folder) {
  // The lab: a plain name with its default config in the tree (the scripts quote it as is).
  const bool plain = !lab.empty() && std::all_of(lab.begin(), lab.end(), [](unsigned char c) {
    return std::isalnum(c) || c == '_' || c == '-';
  });
  if (!plain) fail(zip_path, "\"" + lab + "\" is not a lab name");
  const fs::path config_file = (lab_folder.empty() ? fs::path(source_dir) / "labs" / lab : fs::path(lab_folder)) / (lab + ".json");
  if (!fs::is_regular_file(config_file)) fail(zip_path, "no lab config " + config_file.string());
  nlohmann::json config;
  try {
    config = nlohmann::json::parse(readFile(config_file, zip_path));
  } catch (const nlohmann::json::exception& e) {
    fail(zip_path, config_file.string() + ": " + e.what());
  }

  const bool model_files = config.contains("model_file");
  std::vector<Entry> entries = {{"setup.sh", setupScript(model_files), 0755u},
                                {"run_autograder", runScript(lab), 0755u},
                                {"README.md", readme(lab, config), 0644u}};
  // A lab with a plant per student (labs/variants.h): the course secret rides in the staff-only zip,
  // and run_autograder grades each submission on its submitter's plant.
  if (config.contains("variants")) {
    const std::string secret = courseSecret();
    if (secret.empty())
      fail(zip_path, lab + " gives each student their own plant: set DYNLAB_COURSE_SECRET (the secret the students' keys "
                           "were made with) when writing its autograder");
    entries.push_back({"course_secret", secret, 0600u});
  }
  addSourceTree(source_dir, zip_path, entries);
  if (!lab_folder.empty()) {
    if (std::any_of(entries.begin(), entries.end(), [&](const Entry& e) { return e.name.rfind("source/labs/" + lab + "/", 0) == 0; }))
      fail(zip_path, "the dynlab tree has a folder labs/" + lab + " already");
    addLabFolder(lab_folder, lab, zip_path, entries);
  }
  // The zip being written may sit inside the tree: never pack it (or its temp file) into itself.
  const fs::path out = fs::weakly_canonical(zip_path);
  std::erase_if(entries, [&](const Entry& e) {
    if (e.name.rfind("source/", 0) != 0) return false;
    const fs::path p = fs::weakly_canonical(fs::path(source_dir) / e.name.substr(7));
    return p == out || p.string() == out.string() + ".tmp";
  });
  writeZip(std::move(entries), zip_path);
}

}  // namespace dyn::app
