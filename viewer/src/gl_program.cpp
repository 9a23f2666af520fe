// Shader programs and the planar shadow (gl_program.hpp).

#include "gl_program.hpp"

#include <string>

namespace mm::viewer {
namespace {

// The shader or program if its compile or link status is good; else deleted, and an error with
// the driver's log after `failure`.
template <class GetStatus, class GetLog, class Delete>
Result<GLuint> checked(GLuint object, GLenum status, GetStatus get_status, GetLog get_log,
                       Delete destroy, const std::string& failure) {
  GLint ok = 0;
  get_status(object, status, &ok);
  if (ok) return object;
  char log[2048] = {};
  get_log(object, sizeof log, nullptr, log);
  destroy(object);
  return Error{failure + log};
}

Result<GLuint> compile(GLenum type, const char* source, const char* name) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  return checked(shader, GL_COMPILE_STATUS, glGetShaderiv, glGetShaderInfoLog, glDeleteShader,
                 std::string("renderer: the ") + name + " shader does not compile: ");
}

}  // namespace

Result<GLuint> link(const char* vertex, const char* fragment, const char* name) {
  Result<GLuint> vs = compile(GL_VERTEX_SHADER, vertex, name);
  if (!vs) return vs.error();
  Result<GLuint> fs = compile(GL_FRAGMENT_SHADER, fragment, name);
  if (!fs) {
    glDeleteShader(*vs);
    return fs.error();
  }
  const GLuint program = glCreateProgram();
  glAttachShader(program, *vs);
  glAttachShader(program, *fs);
  glLinkProgram(program);
  glDeleteShader(*vs);
  glDeleteShader(*fs);
  return checked(program, GL_LINK_STATUS, glGetProgramiv, glGetProgramInfoLog, glDeleteProgram,
                 std::string("renderer: the ") + name + " program does not link: ");
}

glm::mat4 shadow_projection(const glm::vec3& light, float height) {
  glm::mat4 m(1.0f);
  m[1] = glm::vec4(-light.x / light.y, 0.0f, -light.z / light.y, 0.0f);
  m[3] = glm::vec4(light.x / light.y * height, height, light.z / light.y * height, 1.0f);
  return m;
}

}  // namespace mm::viewer
