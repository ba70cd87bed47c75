// The model's MJCF documents as MuJoCo will see them (mjcf3.h's MjcfDocs: tinyxml2, includes walked
// in place) and MuJoCo 2.2.2's own schema, read from what mj_printSchema prints: an element or
// attribute 2.2.2 would reject ("Schema violation: unrecognized attribute: 'kv' Element 'position',
// line 9", naming neither the file nor what it is) is refused here in one line that says which file,
// which line, and that it is syntax of a later MuJoCo. The schema is the installed library's, so this
// check refuses nothing MuJoCo would read.
#include <cstring>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

#include "physics/model_file/mjcf3.h"
#include "physics/model_file/mujoco_call.h"

namespace dyn::model_file::detail {

namespace {

using tinyxml2::XMLElement;

// MuJoCo 2.2.2's schema: per element, its attributes and the elements it may hold.
struct Schema {
  struct Node {
    std::unordered_set<std::string> attributes;
    std::unordered_map<std::string, int> children;
  };
  std::vector<Node> nodes;  // [0]: the root, <mujoco>

  // mj_printSchema's text: one element a line, indented 3 spaces a level, its name, a "(?)"-like
  // count, then its attributes from column 30 on, continued on lines indented 30 spaces; "(R)" marks an
  // element that may hold itself, "(world)body" is <worldbody> and <body>.
  Schema() {
    std::vector<char> text(1 << 20, '\0');
    mj_printSchema(nullptr, text.data(), int(text.size()), 0, 0);
    std::istringstream lines(text.data());
    std::vector<int> stack;  // open elements by level
    std::string line;
    while (std::getline(lines, line)) {
      const std::size_t indent = line.find_first_not_of(' ');
      if (indent == std::string::npos) continue;
      std::istringstream words(line.substr(indent));
      std::string word;
      if (indent < 30) {
        std::string name, count;
        words >> name >> count;
        const std::size_t level = indent / 3;
        stack.resize(level);
        nodes.emplace_back();
        const int id = int(nodes.size()) - 1;
        if (!stack.empty()) {
          Node& parent = nodes[std::size_t(stack.back())];
          if (name == "(world)body") parent.children["worldbody"] = id, name = "body";
          parent.children[name] = id;
        }
        if (count == "(R)") nodes[std::size_t(id)].children[name] = id;
        stack.push_back(id);
      }
      while (!stack.empty() && words >> word) nodes[std::size_t(stack.back())].attributes.insert(word);
    }
  }
};

const Schema& schema() {
  static const Schema s;
  return s;
}

// What dynlab translates from MuJoCo 3, named in the refusal of what it does not.
constexpr const char* kTranslated =
    "dynlab translates site1/site2 on <connect> and <weld>, kv, dampratio and inheritrange on <position>, <size memory>, integrator "
    "implicitfast and MuJoCo 3's autolimits default";

void checkElement(MjcfDocs& docs, XMLElement* e, int node) {
  const Schema& s = schema();
  const Schema::Node& n = s.nodes[std::size_t(node)];
  for (const tinyxml2::XMLAttribute* a = e->FirstAttribute(); a; a = a->Next())
    if (!n.attributes.count(a->Name()))
      throw ModelFileError(docs.where(e) + ": attribute '" + oneLine(a->Name()).substr(0, 80) + "' of <" + e->Name() +
                           "> is MuJoCo 3.x syntax that Debian's MuJoCo 2.2.2 does not read (or a misspelling: 2.2.2's "
                           "schema has no such attribute there); " + kTranslated + "; write it in MuJoCo 2.2.2's terms or leave it out");
  docs.children(e, [&](XMLElement* c) {
    const auto it = n.children.find(c->Name());
    if (it == n.children.end())
      throw ModelFileError(docs.where(c) + ": element <" + oneLine(c->Name()).substr(0, 80) + "> inside <" + e->Name() +
                           "> is MuJoCo 3.x syntax that Debian's MuJoCo 2.2.2 does not read (or a misspelling: 2.2.2's "
                           "schema has no such element there); " + kTranslated + "; write it in MuJoCo 2.2.2's terms or leave it out");
    checkElement(docs, c, it->second);
  });
}

}  // namespace

MjcfDocs::MjcfDocs(const std::string& p, const std::string& text, mjVFS* v) : path(p), vfs(v) {
  Doc main;
  main.who = path;
  main.vfsname = path;
  main.doc = std::make_unique<tinyxml2::XMLDocument>();
  main.doc->Parse(text.data(), text.size());
  mjcf_ = !main.doc->Error() && main.doc->RootElement() && std::strcmp(main.doc->RootElement()->Name(), "mujoco") == 0;
  docs.push_back(std::move(main));
}

std::string MjcfDocs::where(const XMLElement* e) const {
  for (const Doc& d : docs)
    if (d.doc.get() == e->GetDocument()) return d.who + ": line " + std::to_string(e->GetLineNum());
  return path;
}

MjcfDocs::Doc& MjcfDocs::docOf(const tinyxml2::XMLNode* e) {
  for (Doc& d : docs)
    if (d.doc.get() == e->GetDocument()) return d;
  return docs[0];
}

// The root element of the file an <include> names, parsed once; null when MuJoCo will say why not.
XMLElement* MjcfDocs::included(const XMLElement* include) {
  const char* file = include->Attribute("file");
  if (!file) return nullptr;
  const int at = mj_findFileVFS(vfs, file);
  if (at < 0) return nullptr;
  auto it = by_vfs_.find(at);
  if (it == by_vfs_.end()) {
    Doc d;
    d.who = path + ": included '" + oneLine(file).substr(0, 200) + "'";
    d.vfsname = vfs->filename[at];
    d.doc = std::make_unique<tinyxml2::XMLDocument>();
    d.doc->Parse(static_cast<const char*>(vfs->filedata[at]), std::size_t(vfs->filesize[at]));
    docs.push_back(std::move(d));
    it = by_vfs_.emplace(at, docs.size() - 1).first;
  }
  const tinyxml2::XMLDocument& doc = *docs[it->second].doc;
  return doc.Error() ? nullptr : const_cast<XMLElement*>(doc.RootElement());
}

void MjcfDocs::children(XMLElement* e, const std::function<void(XMLElement*)>& f, int depth) {
  for (XMLElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) {
    if (std::strcmp(c->Name(), "include") != 0) {
      f(c);
      continue;
    }
    // checkSizes bounded the nesting already; this bound only keeps a walk from looping.
    if (depth < kMaxIncludeDepth)
      if (XMLElement* r = included(c)) children(r, f, depth + 1);
  }
}

namespace {
// A printer that notes, for each element, the line it prints it on and the line it was written on.
class LinePrinter : public tinyxml2::XMLPrinter {
 public:
  std::vector<int> lines{0, 0};
  bool VisitEnter(const XMLElement& e, const tinyxml2::XMLAttribute* a) override {
    const bool more = XMLPrinter::VisitEnter(e, a);
    const char* text = CStr();
    for (; counted_ < std::size_t(CStrSize() > 0 ? CStrSize() - 1 : 0); ++counted_)
      if (text[counted_] == '\n') lines.push_back(0);
    if (lines.back() == 0) lines.back() = e.GetLineNum();
    return more;
  }

 private:
  std::size_t counted_ = 0;
};
}  // namespace

void MjcfDocs::store() {
  for (Doc& d : docs) {
    if (!d.changed) continue;
    LinePrinter printer;
    d.doc->Print(&printer);
    if (&d == &docs[0]) lines = printer.lines;
    const std::string text(printer.CStr(), std::size_t(printer.CStrSize() > 0 ? printer.CStrSize() - 1 : 0));
    // In place: 2.2.2's mj_deleteFileVFS can loop forever (fixed in MuJoCo 2.3.2).
    const int at = mj_findFileVFS(vfs, d.vfsname.c_str());
    if (at < 0) throw ModelFileError(d.who + ": lost from MuJoCo's virtual file system");
    void* data = mju_malloc(text.size());
    std::memcpy(data, text.data(), text.size());
    mju_free(vfs->filedata[at]);
    vfs->filedata[at] = data;
    vfs->filesize[at] = int(text.size());
    d.changed = false;
  }
}

void checkSchema(MjcfDocs& docs) {
  if (!docs.mjcf()) return;
  checkElement(docs, docs.root(), 0);
}

}  // namespace dyn::model_file::detail
