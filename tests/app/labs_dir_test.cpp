// Labs outside the dynlab tree (labs/generic/lab_folders.h, app/cli/lab_options.h), as a lecturer keeps
// them: `dynlab new-lab x --from fivebar --labs DIR` prints the command to run next, which runs as
// printed (parsed as a shell would, run as an argument vector); `dynlab list --labs DIR` shows the
// tree's labs and x; DYNLAB_LABS names several folders; a name clash is one line and exit 2; a model
// path resolves in the lab's folder first, then the tree, and one that links out of both is refused;
// check-lab fails on a handout that does not build and on a README that is not the lab's.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>
#include <sys/stat.h>

#include <sstream>

#include "tests/app/cli_run.h"

using namespace dyn::test::cli;
using json = nlohmann::json;

namespace {

// A POSIX shell's word splitting of a plain command line: words split at spaces, '...' quoted
// literally, a backslash escaping the next character outside quotes. No expansion (none is printed).
std::vector<std::string> shellWords(const std::string& line) {
  std::vector<std::string> words;
  std::string word;
  bool in_word = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (c == '\'') {
      const std::size_t end = line.find('\'', i + 1);
      REQUIRE_MESSAGE(end != std::string::npos, "unterminated quote in: " << line);
      word += line.substr(i + 1, end - i - 1), i = end, in_word = true;
    } else if (c == '\\' && i + 1 < line.size()) {
      word += line[++i], in_word = true;
    } else if (c == ' ') {
      if (in_word) words.push_back(word);
      word.clear(), in_word = false;
    } else {
      word += c, in_word = true;
    }
  }
  if (in_word) words.push_back(word);
  return words;
}

// The line of out that starts (after its indent) with a word ending "dynlab" and holds `what`.
std::string commandLine(const std::string& out, const std::string& what) {
  std::istringstream lines(out);
  for (std::string line; std::getline(lines, line);) {
    const std::string bare = line.substr(std::min(line.find_first_not_of(' '), line.size()));
    const std::vector<std::string> words = bare.empty() ? std::vector<std::string>{} : shellWords(bare);
    if (!words.empty() && fs::path(words[0]).filename() == "dynlab" && bare.find(what) != std::string::npos) return bare;
  }
  return "";
}

// new-lab NAME --from fivebar into `labs` (no next-step parsing); the lab's folder.
fs::path newLab(const TempDir& dir, const std::string& name, const fs::path& labs) {
  fs::create_directories(labs);
  const Result r = dynlab(dir, {"new-lab", name, "--from", "fivebar", "--labs", labs.string()});
  INFO(r.out, r.err);
  REQUIRE(r.code == 0);
  return labs / name;
}

// Lines of `dynlab list` output: name → the rest of its line.
std::map<std::string, std::string> listed(const std::string& out) {
  std::map<std::string, std::string> labs;
  std::istringstream lines(out);
  for (std::string line; std::getline(lines, line);)
    if (const auto space = line.find(' '); space != std::string::npos) labs[line.substr(0, space)] = line.substr(space);
  return labs;
}

}  // namespace

TEST_CASE("new-lab --labs DIR: the next step printed runs as printed; list shows the tree's labs and the new one") {
  const TempDir dir("labs_dir_next");
  // A folder name a shell would split: the printed command must quote it.
  const fs::path labs = dir / "my course's labs";
  fs::create_directories(labs);
  Result r = dynlab(dir, {"new-lab", "trammel", "--from", "fivebar", "--labs", labs.string()});
  INFO(r.out, r.err);
  REQUIRE(r.code == 0);
  CHECK(fs::exists(labs / "trammel/trammel.json"));
  const std::string next = commandLine(r.out, "check-lab");
  REQUIRE_MESSAGE(!next.empty(), "no command line in:\n" << r.out);
  const std::vector<std::string> argv = shellWords(next);
  CHECK(argv == std::vector<std::string>{argv[0], "check-lab", "trammel", "--labs", labs.string()});

  // Run exactly that, from the same folder: the contract, the handout and the README all pass.
  r = run(dir, argv, [] {
    ProcessOptions o;
    o.timeout_s = 900;
    return o;
  }());
  INFO(r.out, r.err);
  CHECK(r.code == 0);
  CHECK(r.out.find("FAIL") == std::string::npos);
  for (const char* check : {"config ", "engines ", "grading ", "handout ", "readme ", "cli "}) {
    INFO("check ", check);
    CHECK(r.out.find("  ok    " + std::string(check)) != std::string::npos);
  }

  // The tree's labs stay visible beside the new one, which says where it is.
  r = dynlab(dir, {"list", "--labs", labs.string()});
  REQUIRE(r.code == 0);
  const auto names = listed(r.out);
  for (const char* tree : {"fivebar", "puma_motion", "puma_impedance", "slider_crank", "grasp"}) CHECK(names.count(tree) == 1);
  REQUIRE(names.count("trammel") == 1);
  CHECK(names.at("trammel").find((labs / "trammel").string()) != std::string::npos);
  CHECK(names.at("fivebar").find('[') == std::string::npos);  // a tree lab: no folder shown

  // Without the folder the lab is unknown, and the message says how to name one.
  r = dynlab(dir, {"run", "trammel", "--duration", "0.01"});
  CHECK(r.code == 2);
  CHECK(r.err.find("--labs DIR") != std::string::npos);
}

TEST_CASE("DYNLAB_LABS: two folders, both searched after the tree (relative paths, from any folder dynlab starts in)") {
  const TempDir dir("labs_dir_env");
  newLab(dir, "alpha", dir / "a");
  newLab(dir, "beta", dir / "b");
  const ProcessOptions env = withEnv({{"DYNLAB_LABS", "a::b"}});  // an empty entry is skipped
  Result r = dynlab(dir, {"list"}, env);
  INFO(r.out, r.err);
  REQUIRE(r.code == 0);
  const auto names = listed(r.out);
  for (const char* lab : {"alpha", "beta", "fivebar", "slider_crank"}) CHECK(names.count(lab) == 1);
  for (const char* lab : {"alpha", "beta"}) {
    r = dynlab(dir, {"run", lab, "--engine", "hand", "--duration", "0.05", "--out", std::string("run_") + lab}, env);
    INFO(r.err);
    CHECK(r.code == 0);
    CHECK(json::parse(readFile(dir / ("run_" + std::string(lab)) / "summary.json"))["lab"] == lab);
  }
  // --labs beside DYNLAB_LABS; the same folder named twice is one folder, not a clash.
  fs::create_directories(dir / "c");
  newLab(dir, "gamma", dir / "c");
  r = dynlab(dir, {"list", "--labs", "c", "--labs", (dir / "a").string()}, env);
  INFO(r.err);
  CHECK(r.code == 0);
  CHECK(listed(r.out).count("gamma") == 1);
  // The tree's own labs/ given as a folder is the tree (no clash with itself).
  r = dynlab(dir, {"list", "--labs", std::string(DYNLAB_SOURCE_DIR) + "/labs"});
  CHECK(r.code == 0);
  // new-lab without --labs writes into the first DYNLAB_LABS folder, and says the next step without it.
  r = dynlab(dir, {"new-lab", "delta", "--from", "alpha"}, env);
  INFO(r.out, r.err);
  REQUIRE(r.code == 0);
  CHECK(fs::exists(dir / "a/delta/delta.json"));
  const std::vector<std::string> next = shellWords(commandLine(r.out, "check-lab"));
  CHECK(std::vector<std::string>(next.begin() + 1, next.end()) == std::vector<std::string>{"check-lab", "delta"});
}

TEST_CASE("a lab outside the tree may not take a name another lab has: one line, exit 2") {
  const TempDir dir("labs_dir_clash");
  // A copy of the tree's five-bar, under its own name.
  fs::create_directories(dir / "mine");
  fs::copy(fs::path(DYNLAB_SOURCE_DIR) / "labs/fivebar", dir / "mine/fivebar", fs::copy_options::recursive);
  for (const auto& cmd : std::vector<std::vector<std::string>>{{"list"}, {"run", "fivebar", "--duration", "0.01"}, {"check-lab", "fivebar"}}) {
    INFO(shown(cmd));
    checkRefused(dynlab(dir, cat(cmd, {"--labs", "mine"})),
                        {"--labs", (dir / "mine/fivebar").string(), "the dynlab tree's lab fivebar", std::string(DYNLAB_SOURCE_DIR) + "/labs/fivebar"});
  }
  // Two outside folders with the same name in them: both named.
  newLab(dir, "twin", dir / "one");
  newLab(dir, "twin", dir / "two");
  checkRefused(dynlab(dir, {"list"}, withEnv({{"DYNLAB_LABS", (dir / "one").string() + ":" + (dir / "two").string()}})),
                      {"<environment>", "DYNLAB_LABS", (dir / "two/twin").string(), (dir / "one").string()});
  // A folder that is not there, and a lab folder named unlike a lab.
  checkRefused(dynlab(dir, {"list", "--labs", "missing"}), {"--labs", "expected an existing folder", "missing"});
  fs::create_directories(dir / "odd/Odd");
  writeFile(dir / "odd/Odd/Odd.json", "{}");
  checkRefused(dynlab(dir, {"list", "--labs", "odd"}), {"--labs", "Odd", "lowercase"});
}

TEST_CASE("a relative model path resolves in the lab's folder first, then the tree; one linking out of both is refused") {
  const TempDir dir("labs_dir_model");
  const fs::path lab = newLab(dir, "shadow", dir / "labs");
  const fs::path config = lab / "shadow.json";
  json d = json::parse(readFile(config));
  const std::vector<std::string> labs = {"--labs", (dir / "labs").string()};
  const auto runIt = [&] { return dynlab(dir, cat({"run", "shadow", "--engine", "hand", "--duration", "0.05", "--out", "run"}, labs)); };

  // The tree has assets/models/fourbar.xml (one crank); the lab's folder has a file of that path
  // holding the five-bar. The lab's own wins: the five-bar's joints are found.
  fs::create_directories(lab / "assets/models");
  fs::rename(lab / "fivebar.xml", lab / "assets/models/fourbar.xml");
  d["model_file"] = "assets/models/fourbar.xml";
  writeFile(config, d.dump(1));
  Result r = runIt();
  INFO(r.err);
  CHECK(r.code == 0);
  CHECK(readCsv(dir / "run/trace_hand.csv").col("tau_left_crank") >= 0);

  // Not in the lab's folder: the tree's, read (the four-bar's bodies and joints are not the five-bar's:
  // refused, listing the four-bar's, whose crank is plain "crank").
  fs::remove(lab / "assets/models/fourbar.xml");
  r = runIt();
  CHECK(r.code == 2);
  CHECK(r.err.find("(crank") != std::string::npos);
  CHECK(r.err.find("not found") == std::string::npos);

  // In neither: one line naming the file, the JSON path and both places looked in.
  d["model_file"] = "nowhere.xml";
  writeFile(config, d.dump(1));
  r = runIt();
  CHECK(r.code == 2);
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  for (const std::string& s : {config.string(), std::string("/model_file"), lab.string(), std::string(DYNLAB_SOURCE_DIR)})
    CHECK_MESSAGE(r.err.find(s) != std::string::npos, "missing: " << s << " in " << r.err);

  // A file that links out of both folders (the scratch folder is inside the build tree: this one is
  // not), and a path climbing out: refused at /model_file.
  const fs::path elsewhere = fs::temp_directory_path() / ("dynlab_labs_dir_" + std::to_string(::getpid()));
  fs::create_directories(elsewhere);
  fs::copy_file(fs::path(DYNLAB_SOURCE_DIR) / "labs/fivebar/fivebar.xml", elsewhere / "fivebar.xml", fs::copy_options::overwrite_existing);
  fs::create_symlink(elsewhere / "fivebar.xml", lab / "linked.xml");
  for (const std::string path : {"linked.xml", "../../elsewhere/fivebar.xml"}) {
    d["model_file"] = path;
    writeFile(config, d.dump(1));
    r = runIt();
    INFO(path, ": ", r.err);
    CHECK(r.code == 2);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    CHECK(r.err.find(config.string()) != std::string::npos);
    CHECK(r.err.find("/model_file") != std::string::npos);
    CHECK(r.err.find("expected a model file") != std::string::npos);
  }
  fs::remove_all(elsewhere);
}

TEST_CASE("check-lab builds the handout and checks the README: either broken fails it, naming what") {
  const TempDir dir("labs_dir_prose");
  const fs::path lab = newLab(dir, "zither", dir / "labs");
  const std::vector<std::string> check = {"check-lab", "zither", "--skip-cli", "--labs", (dir / "labs").string()};
  // A placeholder naming nothing in the JSON (what a JSON edit leaves behind), and a README that is not UTF-8.
  writeFile(lab / "handout.md", readFile(lab / "handout.md") + "\nThe third crank is {/actuated/2}.\n");
  writeFile(lab / "README.md", "# Lab: zither \xE9t\xE9\n");
  ProcessOptions slow;
  slow.timeout_s = 900;
  Result r = dynlab(dir, check, slow);
  INFO(r.out, r.err);
  CHECK(r.code == 1);
  std::string handout, readme;
  std::istringstream lines(r.out);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("  FAIL  handout", 0) == 0) handout = line;
    if (line.rfind("  FAIL  readme", 0) == 0) readme = line;
  }
  CHECK(handout.find("dynlab handout zither") != std::string::npos);
  CHECK(handout.find("{/actuated/2}") != std::string::npos);
  CHECK(handout.find((lab / "handout.md").string()) != std::string::npos);
  CHECK(readme.find((lab / "README.md").string()) != std::string::npos);
  CHECK(readme.find("UTF-8") != std::string::npos);
  CHECK(r.out.find("  ok    config ") != std::string::npos);  // the contract's checks still ran

  // The README copied from another lab, and one that is missing; `dynlab handout` agrees with check-lab.
  writeFile(lab / "handout.md", "## Mechanism\n\nA {/model_file}.\n\n## Exercise\n\nTrack it.\n");
  fs::copy_file(fs::path(DYNLAB_SOURCE_DIR) / "labs/fivebar/README.md", lab / "README.md", fs::copy_options::overwrite_existing);
  r = dynlab(dir, check, slow);
  CHECK(r.out.find("  ok    handout ") != std::string::npos);
  CHECK(r.out.find("  FAIL  readme") != std::string::npos);
  CHECK(r.out.find("expected the lab's name zither") != std::string::npos);
  CHECK(r.code == 1);
  CHECK(dynlab(dir, {"handout", "zither", "--labs", (dir / "labs").string(), "--out", "h"}).code == 0);
  fs::remove(lab / "README.md");
  r = dynlab(dir, check, slow);
  CHECK(r.code == 1);
  CHECK(r.out.find("  FAIL  readme") != std::string::npos);
  CHECK(r.out.find((lab / "README.md").string()) != std::string::npos);
  // A lab folder is input: a FIFO as its prose is refused at once (never waited on), naming the file.
  fs::remove(lab / "handout.md");
  REQUIRE(::mkfifo((lab / "handout.md").c_str(), 0644) == 0);
  REQUIRE(::mkfifo((lab / "README.md").c_str(), 0644) == 0);
  slow.timeout_s = 120;
  r = dynlab(dir, check, slow);
  CHECK_FALSE(r.timed_out);
  CHECK(r.code == 1);
  for (const char* file : {"handout.md", "README.md"}) {
    INFO(file, "\n", r.out);
    CHECK(r.out.find((lab / file).string() + ": /: expected a regular file") != std::string::npos);
  }
  r = dynlab(dir, cat({"handout", "zither", "--out", "h2"}, {"--labs", (dir / "labs").string()}), slow);
  CHECK(r.code == 2);
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
}

TEST_CASE("a lab outside the tree grades with a replay line that runs as printed, in a batch, and packs into the autograder") {
  const TempDir dir("labs_dir_grade");
  const fs::path lab = newLab(dir, "outside", dir / "labs");
  const std::vector<std::string> labs = {"--labs", (dir / "labs").string()};
  Result r = dynlab(dir, cat({"grade", (lab / "examples/joint_pd.json").string(), "--out", "g", "--no-plots"}, labs));
  INFO(r.out, r.err);
  REQUIRE(r.code == 0);
  const std::string replay = commandLine(r.out.substr(r.out.find("replay:") + 7), "--replay");
  REQUIRE(!replay.empty());
  r = run(dir, shellWords(replay));
  INFO(replay, "\n", r.out, r.err);
  CHECK(r.code == 0);
  CHECK(r.out.find("replay: match") != std::string::npos);

  // A batch grades each submission in a process of its own: each finds the lab too. The copy keeps
  // the five-bar's plant per student, so the batch grades each file's student (its name) with the
  // course secret.
  const ProcessOptions staff = withEnv({{"DYNLAB_COURSE_SECRET", "labs-dir-test"}});
  fs::create_directories(dir / "subs");
  for (const char* f : {"joint_pd.json", "task_pd.json"}) fs::copy_file(lab / "examples" / f, dir / "subs" / f);
  r = dynlab(dir, cat({"grade", "--batch", "subs", "--out", "batch", "--no-plots"}, labs), staff);
  INFO(r.out, r.err);
  CHECK(r.code == 0);
  for (const char* f : {"joint_pd", "task_pd"}) {
    const json results = json::parse(readFile(dir / "batch" / f / "results.json"));
    CHECK(results["score"].get<double>() > 0);
  }

  // The autograder bundle carries the lab's folder in its tree (names are stored plainly in a zip),
  // without its instructor answers.
  r = dynlab(dir, cat({"autograder", "outside", "--out", "outside.zip"}, labs), staff);
  INFO(r.err);
  REQUIRE(r.code == 0);
  const std::string zip = readFile(dir / "outside.zip");
  CHECK(zip.find("source/labs/outside/outside.json") != std::string::npos);
  CHECK(zip.find("source/labs/outside/examples/joint_pd.json") != std::string::npos);
  CHECK(zip.find("source/labs/outside/instructor/") == std::string::npos);
  CHECK(zip.find("source/labs/fivebar/fivebar.json") != std::string::npos);

  // The window is another program (dynlab-ui, exec'd by dynlab ui): it is told the folders too.
  if (haveXvfb()) {
    r = run(dir, inXvfb({DYNLAB_BIN, "ui", "outside", "--labs", (dir / "labs").string(), "--frames", "2"}));
    INFO(r.out, r.err);
    CHECK(r.code == 0);
    CHECK(r.out.find("dynlab-ui: 2 frames") != std::string::npos);
  }
}
