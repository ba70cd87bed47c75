// The README routes every reader to docs/ and the labs' READMEs: each relative link (and each
// #anchor, as GitHub derives it from a heading) must resolve, and the README stays a landing page.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <set>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

const fs::path kRoot = DYNLAB_SOURCE_DIR;

std::string readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::string line;
  for (char c : text) {
    if (c == '\n') out.push_back(std::move(line)), line.clear();
    else line += c;
  }
  out.push_back(line);
  return out;
}

// The prose lines of a Markdown file: no fenced or indented code, inline code spans removed.
std::vector<std::string> prose(const std::string& text) {
  std::vector<std::string> out;
  bool fenced = false;
  for (const std::string& l : lines(text)) {
    if (l.rfind("```", 0) == 0) {
      fenced = !fenced;
      continue;
    }
    if (fenced || l.rfind("    ", 0) == 0) continue;
    out.push_back(std::regex_replace(l, std::regex("`[^`]*`"), ""));
  }
  return out;
}

// GitHub's anchor of a heading: lower case, punctuation dropped, spaces as hyphens (letters of any
// script kept; the dashes, arrows and quotes these docs use dropped).
std::string slug(const std::string& heading) {
  static const std::vector<std::string> kDropped = {"—", "–", "→", "…", "’", "“", "”", "×", "·", "≥", "≤", "∝"};
  std::string out;
  for (std::size_t i = 0; i < heading.size();) {
    const unsigned char c = static_cast<unsigned char>(heading[i]);
    if (c >= 0x80) {
      std::size_t n = c >= 0xF0 ? 4 : c >= 0xE0 ? 3 : 2;
      const std::string ch = heading.substr(i, n);
      bool drop = false;
      for (const auto& d : kDropped) drop = drop || ch == d;
      if (!drop) out += ch;
      i += n;
      continue;
    }
    if (std::isalnum(c) || c == '-' || c == '_') out += char(std::tolower(c));
    else if (c == ' ') out += '-';
    ++i;
  }
  return out;
}

std::set<std::string> anchors(const fs::path& md) {
  std::set<std::string> out;
  for (const std::string& l : prose(readFile(md))) {
    const std::size_t hashes = l.find_first_not_of('#');
    if (hashes == 0 || hashes == std::string::npos || hashes > 6 || l[hashes] != ' ') continue;
    std::string base = slug(l.substr(hashes + 1)), a = base;
    for (int k = 1; out.count(a); ++k) a = base + "-" + std::to_string(k);  // repeated headings: -1, -2
    out.insert(a);
  }
  return out;
}

std::vector<fs::path> documents() {
  std::vector<fs::path> docs = {kRoot / "README.md"};
  for (const auto& e : fs::directory_iterator(kRoot / "docs"))
    if (e.path().extension() == ".md") docs.push_back(e.path());
  for (const auto& e : fs::directory_iterator(kRoot / "labs"))
    if (fs::exists(e.path() / "README.md")) docs.push_back(e.path() / "README.md");
  return docs;
}

}  // namespace

TEST_CASE("the anchor rule: GitHub's slugs of these docs' headings") {
  CHECK(slug("3. The mechanisms") == "3-the-mechanisms");
  CHECK(slug("Adding a lab (the lab contract)") == "adding-a-lab-the-lab-contract");
  CHECK(slug("Accuracy against speed") == "accuracy-against-speed");
}

TEST_CASE("every relative link and anchor in README.md, docs/ and the labs' READMEs resolves") {
  const std::regex link(R"(\]\(([^)\s]+)\))");
  int checked = 0;
  for (const fs::path& doc : documents()) {
    for (const std::string& l : prose(readFile(doc))) {
      for (auto m = std::sregex_iterator(l.begin(), l.end(), link); m != std::sregex_iterator(); ++m) {
        const std::string target = (*m)[1];
        if (target.rfind("http://", 0) == 0 || target.rfind("https://", 0) == 0 || target.rfind("mailto:", 0) == 0) continue;
        const std::size_t hash = target.find('#');
        const std::string file = target.substr(0, hash), anchor = hash == std::string::npos ? "" : target.substr(hash + 1);
        const fs::path resolved = file.empty() ? doc : doc.parent_path() / file;
        INFO(doc.lexically_relative(kRoot).string(), ": ", target);
        CHECK(fs::exists(resolved));
        if (!anchor.empty() && fs::exists(resolved) && resolved.extension() == ".md") CHECK(anchors(resolved).count(anchor) == 1);
        ++checked;
      }
    }
  }
  CHECK(checked > 40);
}

TEST_CASE("the README is a landing page: short, the two commands, a link for each reader") {
  const std::string readme = readFile(kRoot / "README.md");
  CHECK(lines(readme).size() <= 250);
  CHECK(readme.find("scripts/demo") != std::string::npos);
  CHECK(readme.find("scripts/test") != std::string::npos);
  for (const char* guide : {"docs/student.md", "docs/teaching.md", "docs/architecture.md", "docs/performance.md", "docs/labs.md"})
    CHECK(readme.find(guide) != std::string::npos);
}
