// MuJoCo 3 syntax read by Debian's MuJoCo 2.2.2 (mjcf3.cpp translates, mjcf3_schema.cpp refuses what
// is left): the model's MJCF text and the files it includes, parsed by tinyxml2 (the XML library
// MuJoCo itself links) in the parser's child, walked as MuJoCo will see them (each <include> replaced
// by its file's elements), changed where MuJoCo 3 means something 2.2.2 can say, and put back into
// MuJoCo's virtual file system in place of the originals (never written to disk).
#pragma once
#include <mujoco/mujoco.h>
#include <tinyxml2.h>

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace dyn::model_file::detail {

// The model's MJCF documents: [0] the model file, then each file it includes (parsed once each).
struct MjcfDocs {
  struct Doc {
    std::string who;      // for errors: "FILE" or "FILE: included 'NAME'"
    std::string vfsname;  // its name in the virtual file system
    std::unique_ptr<tinyxml2::XMLDocument> doc;
    bool changed = false;
  };
  MjcfDocs(const std::string& path, const std::string& text, mjVFS* vfs);
  bool mjcf() const { return mjcf_; }  // false: URDF or not well-formed (left to MuJoCo)
  tinyxml2::XMLElement* root() { return docs[0].doc->RootElement(); }
  // Where an element is written, for errors: "FILE: line N" or "FILE: included 'NAME', line N".
  std::string where(const tinyxml2::XMLElement* e) const;
  Doc& docOf(const tinyxml2::XMLNode* e);
  // e's child elements as MuJoCo sees them: an <include> stands for its file's top elements.
  void children(tinyxml2::XMLElement* e, const std::function<void(tinyxml2::XMLElement*)>& f, int depth = 0);
  // The changed documents printed back into the virtual file system in place of the originals.
  void store();
  // When the model file was printed back: its printed lines' numbers as written ([n]: line n's; 0: none).
  std::vector<int> lines;

  std::string path;
  mjVFS* vfs;
  std::vector<Doc> docs;

 private:
  tinyxml2::XMLElement* included(const tinyxml2::XMLElement* include);
  std::map<int, std::size_t> by_vfs_;  // virtual file index -> docs index
  bool mjcf_ = false;
};

// Every element and attribute of the documents checked against MuJoCo 2.2.2's own schema
// (mj_printSchema): an unknown one is refused in one line naming the file, the line, the element and
// the attribute (mjcf3_schema.cpp).
void checkSchema(MjcfDocs& docs);

// What translateMjcf3 did: notes for the warnings, and the model file's lines when it was rewritten.
struct Mjcf3 {
  std::string notes;
  std::vector<int> lines;  // as MjcfDocs::lines
  // MuJoCo's message with each "line N" of the rewritten model file given as the file's own line (an
  // included element's line MuJoCo gives as 0: left so).
  std::string ownLines(const std::string& message) const;
};

// In the parser's child, before MuJoCo parses: MuJoCo 3 syntax translated into 2.2.2's (the list is
// at the top of mjcf3.cpp) and the rest checked against 2.2.2's schema; the translated texts put into
// vfs in place of the originals. `compile` compiles what vfs holds then (a first pass that site-to-site
// equalities, dampratio and inheritrange need: the sites' bodies and frames, the inertia and the
// joints' ranges at qpos0) and throws MuJoCo's error (out.lines is set before it runs).
void translateMjcf3(const std::string& path, const std::string& text, mjVFS* vfs, const std::function<mjModel*()>& compile,
                    Mjcf3& out);

}  // namespace dyn::model_file::detail
