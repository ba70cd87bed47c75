// grading/escape: each format's escaping function against hostile strings (line breaks, backticks,
// markup, headings, formulas, invalid UTF-8, U+2028), checked through what reads the format:
// cmark-gfm for Markdown, nlohmann::json for JSON, a CSV cell's first character for spreadsheets.
#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "grading/escape.h"
#include "grading/report.h"

using namespace dyn;

namespace {

const std::vector<std::string> kHostile = {
    "plain",
    "two\nlines\r\n",
    "`tick` ``double`` ```",
    "<img src=x onerror=alert(1)>",
    "<script>alert(1)</script>",
    "# heading",
    "\n# heading after a newline",
    "=1+1",
    "-2+3",
    "@SUM(A1)",
    "\tTAB",
    "a | b | c",
    "[link](javascript:alert(1))",
    "![img](x.png)",
    "**bold** _em_ ~~strike~~",
    "1. list",
    "> quote",
    "&amp; &lt;",
    "back\\slash\\",
    "bad \xff\xfe utf-8 \xc3",
    "cut mid-character \xe2\x82",
    "line\xe2\x80\xa8separator",
    "bidi \xe2\x80\xae override",
    std::string("nul\0byte", 8),
    "\x1b[31mred\x1b[0m",
    "",
};

// The HTML body cmark-gfm makes of a Markdown snippet.
std::string render(const std::string& md) {
  const std::string page = renderHtml(md);
  const std::size_t at = page.find("<body>\n") + 7;
  return page.substr(at, page.rfind("</body>") - at);
}

// Tags in an HTML fragment, other than those listed (the empty comment mdText puts before an "@",
// rendered as cmark's own comment, is no tag).
int tagsOtherThan(const std::string& html, const std::vector<std::string>& allowed) {
  int n = 0;
  for (std::size_t at = html.find('<'); at != std::string::npos; at = html.find('<', at + 1)) {
    bool ok = html.compare(at, 25, "<!-- raw HTML omitted -->") == 0;
    for (const auto& t : allowed) ok = ok || html.compare(at, t.size(), t) == 0;
    n += !ok;
  }
  return n;
}

}  // namespace

TEST_CASE("UTF-8: validation, and invalid bytes replaced so JSON dumps never throw") {
  CHECK(isValidUtf8("ζ = 0.72, naïve, 😀"));
  CHECK_FALSE(isValidUtf8("\xff"));
  CHECK_FALSE(isValidUtf8("\xc0\xaf"));          // overlong '/'
  CHECK_FALSE(isValidUtf8("\xed\xa0\x80"));      // a surrogate
  CHECK_FALSE(isValidUtf8("\xf4\x90\x80\x80"));  // past U+10FFFF
  CHECK_FALSE(isValidUtf8("\xe2\x82"));          // cut mid-character
  CHECK(jsonText("a\xff" "b") == "a\xEF\xBF\xBD" "b");
  CHECK(jsonText("ζ") == "ζ");
  for (const auto& s : kHostile) {
    INFO(s);
    CHECK(isValidUtf8(jsonText(s)));
    const nlohmann::json j = {{jsonText(s), jsonText(s)}, {"list", {jsonText(s)}}};
    CHECK_NOTHROW(j.dump());
    if (!isValidUtf8(s)) CHECK_THROWS(nlohmann::json(s).dump());  // what nlohmann does with bad bytes
  }
  nlohmann::json bad = {{"k\xff", {"v\xfe", 1}}};
  CHECK_THROWS(bad.dump());
  const nlohmann::json good = jsonSanitized(bad);
  CHECK_NOTHROW(good.dump());
  CHECK(nlohmann::json::parse(good.dump()) == good);
  CHECK(dumpJson(bad).find("\xEF\xBF\xBD") != std::string::npos);  // the second line of defence
}

TEST_CASE("Markdown text: one line, no construct, renders as the text itself") {
  for (const auto& s : kHostile) {
    INFO(s);
    const std::string md = mdText(s);
    CHECK(md.find('\n') == std::string::npos);
    CHECK(md.find('\r') == std::string::npos);
    CHECK(isValidUtf8(md));
    // As a paragraph, a list item and a table cell: nothing but the surrounding structure.
    CHECK(tagsOtherThan(render("x " + md), {"<p>", "</p>"}) == 0);
    CHECK(tagsOtherThan(render(md), {"<p>", "</p>"}) == 0);
    CHECK(tagsOtherThan(render("- " + md), {"<ul>", "</ul>", "<li>", "</li>"}) == 0);
    const std::string table = render("| a | b |\n|---|---|\n| " + md + " | z |\n");
    CHECK(tagsOtherThan(table, {"<table", "</table", "<thead", "</thead", "<tbody", "</tbody", "<tr", "</tr", "<th", "</th", "<td", "</td"}) == 0);
    CHECK(table.find("<td>z</td>") != std::string::npos);  // no | inside broke the row
  }
  CHECK(render(mdText("<img src=x onerror=alert(1)>")) == "<p>&lt;img src=x onerror=alert(1)&gt;</p>\n");
  CHECK(render(mdText("# heading")) == "<p># heading</p>\n");
  CHECK(render(mdText("a\nb")) == "<p>a\\nb</p>\n");
  CHECK(mdText("kp_x = 3.0 (stable, ζ = 0.72)") == "kp_x = 3.0 (stable, ζ = 0.72)");  // readable as it is
  // An email is no link (GFM's autolinker sees through a backslash escape, not through a comment),
  // and its text stays on the page; an "@" that starts the text needs nothing (no local part).
  for (const std::string email : {"mail me@evil.example now", "a.b+c@x.org", "@SUM(A1)", "x @ y"}) {
    INFO(email);
    const std::string html = render(mdText(email));
    CHECK(html.find("mailto:") == std::string::npos);
    CHECK(html.find("<a") == std::string::npos);
    std::string shown = html;
    for (std::size_t at; (at = shown.find("<!-- raw HTML omitted -->")) != std::string::npos;) shown.erase(at, 25);
    CHECK(shown == "<p>" + email + "</p>\n");
  }
}

TEST_CASE("Markdown code spans: literal, whatever backticks or bars are inside") {
  for (const auto& s : kHostile) {
    INFO(s);
    const std::string md = mdCode(s);
    CHECK(md.find('\n') == std::string::npos);
    const std::string html = render("file " + md + " end");
    CHECK(tagsOtherThan(html, {"<p>", "</p>", "<code>", "</code>"}) == 0);
    CHECK(html.rfind("<p>file <code>", 0) == 0);
    CHECK(html.find("</code> end</p>") != std::string::npos);
    const std::string table = render("| a | b |\n|---|---|\n| " + md + " | z |\n");
    CHECK(table.find("<td>z</td>") != std::string::npos);
  }
  CHECK(render(mdCode("``x``")) == "<p><code>``x``</code></p>\n");
  CHECK(render(mdCode("<b>")) == "<p><code>&lt;b&gt;</code></p>\n");
}

TEST_CASE("HTML text: the five characters as entities") {
  CHECK(htmlText("<img src=x onerror=alert(1)>") == "&lt;img src=x onerror=alert(1)&gt;");
  CHECK(htmlText("a & b \"c\" 'd'") == "a &amp; b &quot;c&quot; &#39;d&#39;");
  CHECK(isValidUtf8(htmlText("\xff<")));
  // A page's title is plain text too.
  const std::string page = renderHtml("x", "</title><script>alert(1)</script>");
  CHECK(page.find("<script") == std::string::npos);
}

TEST_CASE("terminal text: control characters, separators and bad bytes made visible") {
  CHECK(termText("a\nb\tc\rd") == "a\\nb\\tc\\rd");
  CHECK(termText("\x1b[31mred") == "\\x1B[31mred");
  CHECK(termText("line\xe2\x80\xa8sep") == "line\\u{2028}sep");
  CHECK(termText("bidi\xe2\x80\xae") == "bidi\\u{202E}");
  CHECK(termText("bad\xff") == "bad\\xFF");
  CHECK(termText("ζ = 0.72") == "ζ = 0.72");
  for (const auto& s : kHostile) {
    const std::string t = termText(s);
    for (unsigned char c : t) CHECK((c >= 0x20 && c != 0x7f));
    CHECK(isValidUtf8(t));
  }
}

TEST_CASE("names from files: escaped, and a long one clipped between characters with what was left out") {
  CHECK(termName("crank\x1b]0;x\x07") == "crank\\x1B]0;x\\x07");
  CHECK(termName(std::string(200, 'a')) == std::string(200, 'a'));
  // 200,000 characters: the head and the tail, and how many bytes are not shown.
  const std::string clipped = termName("j" + std::string(200000, 'a') + "z");
  CHECK(clipped.size() < 260);
  CHECK(clipped.rfind("ja", 0) == 0);
  CHECK(clipped.back() == 'z');
  CHECK(clipped.find(" bytes left out) … ") != std::string::npos);
  // Never cut inside an escape: every backslash still starts a whole \xNN or \u{XXXX}.
  for (const std::string& s : {std::string(300, '\x1b'), std::string(100, 'a') + std::string(120, '\x9b') + "\xe2\x80\xae"}) {
    const std::string t = termName(s, 200);
    CHECK(t.size() < 260);
    for (std::size_t i = t.find('\\'); i != std::string::npos; i = t.find('\\', i + 1))
      CHECK_MESSAGE((t.compare(i, 4, "\\x1B") == 0 || t.compare(i, 4, "\\x9B") == 0 || t.compare(i, 9, "\\u{202E}") == 0), t);
    CHECK(isValidUtf8(t));
  }
}

TEST_CASE("CSV fields: quoted when needed, formulas neutralised") {
  CHECK(csvField("plain") == "plain");
  CHECK(csvField("a,b") == "\"a,b\"");
  CHECK(csvField("say \"hi\"") == "\"say \"\"hi\"\"\"");
  CHECK(csvField("two\nlines") == "\"two\nlines\"");
  // Terminal escapes and bidi overrides do not reach a spreadsheet or a `cat gradebook.csv` raw.
  CHECK(csvField("a\x1b]0;title\x07" "b") == "a\\x1B]0;title\\x07b");
  CHECK(csvField("x\u202Ey") == "x\\u{202E}y");
  CHECK(csvField("=1+1") == "'=1+1");
  CHECK(csvField("+1") == "'+1");
  CHECK(csvField("-2+3") == "'-2+3");
  CHECK(csvField("@SUM(A1)") == "'@SUM(A1)");
  CHECK(csvField("\tTAB") == "'\tTAB");
  CHECK(csvField("\r=1") == "\"'\r=1\"");
  CHECK(csvField("=HYPERLINK(\"x\",\"y\")") == "\"'=HYPERLINK(\"\"x\"\",\"\"y\"\")\"");
  CHECK(isValidUtf8(csvField("bad\xff")));
  for (const auto& s : kHostile) {
    const std::string f = csvField(s);
    const char first = f.empty() ? 'x' : f[0] == '"' && f.size() > 1 ? f[1] : f[0];
    CHECK(std::string("=+-@\t\r").find(first) == std::string::npos);
  }
}

TEST_CASE("shell words: plain names as they are, the rest single-quoted") {
  CHECK(shellWord("good.json") == "good.json");
  CHECK(shellWord("my file.json") == "'my file.json'");
  CHECK(shellWord("it's.json") == "'it'\\''s.json'");
  CHECK(shellWord("-rf") == "'-rf'");
}
