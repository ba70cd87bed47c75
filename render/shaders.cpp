// The renderer's programs: lit meshes (directional light + ambient + soft specular) and
// constant-width polylines expanded to quads in screen space. One text each, compiled as GLSL 3.30
// core (OSMesa, a desktop window) or GLSL ES 3.00 (WebGL 2) after the header the context names.
#include <stdexcept>
#include <string>

#include "render/gl_internal.h"

namespace dyn::gl {
namespace {

const char* kShadedVertex = R"(layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in float a_end;
uniform mat4 u_view_proj;
uniform mat4 u_model;
uniform mat3 u_normal_matrix;
uniform vec3 u_stretch;  // model-space offset applied to vertices with a_end = 1 (capsules)
out vec3 v_normal;
out vec3 v_world;
invariant gl_Position;  // the translucent colour pass re-draws the depth pass exactly
void main() {
  vec4 world = u_model * vec4(a_position + a_end * u_stretch, 1.0);
  v_world = world.xyz;
  v_normal = u_normal_matrix * a_normal;
  gl_Position = u_view_proj * world;
}
)";

const char* kShadedFragment = R"(in vec3 v_normal;
in vec3 v_world;
uniform vec4 u_color;
uniform vec3 u_light_dir;  // towards the light, world space, unit
uniform vec3 u_view_dir;   // towards the viewer (orthographic)
uniform vec3 u_eye;        // camera position (perspective)
uniform bool u_ortho;
uniform bool u_two_sided;  // a back face seen: lit as the front face turned over
out vec4 frag_color;
void main() {
  vec3 n = normalize(v_normal);
  if (u_two_sided && !gl_FrontFacing) n = -n;
  vec3 v = u_ortho ? u_view_dir : normalize(u_eye - v_world);
  // Soft key light plus a sky/ground ambient so shadowed sides keep their colour.
  float diffuse = max(dot(n, u_light_dir), 0.0);
  float hemi = 0.5 + 0.5 * dot(n, v);
  vec3 h = normalize(u_light_dir + v);
  float spec = pow(max(dot(n, h), 0.0), 48.0);
  vec3 base = u_color.rgb;
  vec3 rgb = base * (0.30 + 0.18 * hemi + 0.62 * diffuse) + vec3(0.16 * spec);
  frag_color = vec4(min(rgb, vec3(1.0)), u_color.a);
}
)";

const char* kLineVertex = R"(layout(location = 0) in vec3 a_position;  // this end of the segment
layout(location = 1) in vec3 a_other;     // the other end
layout(location = 2) in float a_side;     // +1 / -1: which edge of the quad
uniform mat4 u_view_proj;
uniform vec2 u_viewport;   // pixels
uniform float u_half_width;  // pixels
void main() {
  vec4 clip = u_view_proj * vec4(a_position, 1.0);
  vec4 other = u_view_proj * vec4(a_other, 1.0);
  vec2 here_px = clip.xy / clip.w * 0.5 * u_viewport;
  vec2 other_px = other.xy / other.w * 0.5 * u_viewport;
  vec2 d = other_px - here_px;
  vec2 dir = length(d) > 1e-6 ? normalize(d) : vec2(1.0, 0.0);
  // Offset sideways by half the width, and back past the end (square caps close the joints).
  vec2 offset_px = vec2(-dir.y, dir.x) * a_side * u_half_width - dir * u_half_width;
  clip.xy += offset_px / (0.5 * u_viewport) * clip.w;
  gl_Position = clip;
}
)";

const char* kLineFragment = R"(uniform vec4 u_color;
out vec4 frag_color;
void main() { frag_color = u_color; }
)";

// Unless the object's status (compile or link) is set: deletes the object and throws `what` and its
// info log.
template <class GetStatus, class GetLog, class Delete>
void requireStatus(GLuint id, GLenum status, GetStatus get_status, GetLog get_log, Delete remove, const std::string& what) {
  GLint ok = 0;
  get_status(id, status, &ok);
  if (ok) return;
  char log[2048] = {};
  get_log(id, sizeof log, nullptr, log);
  remove(id);
  throw std::runtime_error(what + log);
}

// Compiles one stage; throws with the info log on failure.
GLuint compileStage(GLenum type, const char* source, const char* name) {
  GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  requireStatus(shader, GL_COMPILE_STATUS, glGetShaderiv, glGetShaderInfoLog, glDeleteShader,
                std::string("render: shader '") + name + "' failed: ");
  return shader;
}

// Links a vertex + fragment program (each body after the dialect's header); throws with the info log.
GLuint linkProgram(Glsl dialect, const char* vertex, const char* fragment, const char* name) {
  const std::string header = glslHeader(dialect);
  GLuint vs = compileStage(GL_VERTEX_SHADER, (header + vertex).c_str(), name);
  GLuint fs = compileStage(GL_FRAGMENT_SHADER, (header + fragment).c_str(), name);
  GLuint program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  requireStatus(program, GL_LINK_STATUS, glGetProgramiv, glGetProgramInfoLog, glDeleteProgram,
                std::string("render: program '") + name + "' failed to link: ");
  return program;
}

}  // namespace

ShadedProgram makeShadedProgram(Glsl dialect) {
  ShadedProgram p;
  p.id = linkProgram(dialect, kShadedVertex, kShadedFragment, "shaded");
  p.view_proj = glGetUniformLocation(p.id, "u_view_proj");
  p.model = glGetUniformLocation(p.id, "u_model");
  p.normal_matrix = glGetUniformLocation(p.id, "u_normal_matrix");
  p.stretch = glGetUniformLocation(p.id, "u_stretch");
  p.color = glGetUniformLocation(p.id, "u_color");
  p.light_dir = glGetUniformLocation(p.id, "u_light_dir");
  p.view_dir = glGetUniformLocation(p.id, "u_view_dir");
  p.eye = glGetUniformLocation(p.id, "u_eye");
  p.ortho = glGetUniformLocation(p.id, "u_ortho");
  p.two_sided = glGetUniformLocation(p.id, "u_two_sided");
  return p;
}

LineProgram makeLineProgram(Glsl dialect) {
  LineProgram p;
  p.id = linkProgram(dialect, kLineVertex, kLineFragment, "line");
  p.view_proj = glGetUniformLocation(p.id, "u_view_proj");
  p.viewport = glGetUniformLocation(p.id, "u_viewport");
  p.half_width = glGetUniformLocation(p.id, "u_half_width");
  p.color = glGetUniformLocation(p.id, "u_color");
  return p;
}

}  // namespace dyn::gl

namespace dyn {

const char* glslHeader(Glsl dialect) {
  return dialect == Glsl::Es300 ? "#version 300 es\nprecision highp float;\n" : "#version 330 core\n";
}

const char* glslVersion(Glsl dialect) { return dialect == Glsl::Es300 ? "#version 300 es" : "#version 330 core"; }

}  // namespace dyn
