#include "crowd_renderer.hpp"

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include <glm/gtc/type_ptr.hpp>

#include "gl.hpp"
#include "gl_program.hpp"

namespace mm::viewer {
namespace {

// The same key light as the single character's (renderer.cpp), so the shadows fall alike.
const glm::vec3 kLightDirection = glm::normalize(glm::vec3(0.4f, 1.0f, 0.55f));

// Per vertex: the unit box's position and normal; per instance: the model matrix's columns and
// the colour. `shadow` flattens the placed box onto the ground along the light.
const char* const kVertex = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec4 model0;
layout(location = 3) in vec4 model1;
layout(location = 4) in vec4 model2;
layout(location = 5) in vec4 model3;
layout(location = 6) in vec4 colour;
uniform mat4 view_projection;
uniform mat4 flatten;
out vec3 world_normal;
out vec3 world_position;
out vec3 instance_colour;
void main() {
  mat4 model = mat4(model0, model1, model2, model3);
  vec4 p = flatten * model * vec4(position, 1.0);
  world_position = p.xyz;
  // The columns are orthogonal: the inverse transpose is the matrix over each column's square.
  mat3 m = mat3(model);
  world_normal = m * (normal / vec3(dot(m[0], m[0]), dot(m[1], m[1]), dot(m[2], m[2])));
  instance_colour = colour.rgb;
  gl_Position = view_projection * p;
}
)";

const char* const kFragment = R"(#version 330 core
in vec3 world_normal;
in vec3 world_position;
in vec3 instance_colour;
uniform vec3 light_direction;
uniform vec3 eye;
uniform float shadow;
out vec4 fragment;
void main() {
  if (shadow > 0.5) { fragment = vec4(0.0, 0.0, 0.0, 0.35); return; }
  vec3 n = normalize(world_normal);
  vec3 v = normalize(eye - world_position);
  float key = max(dot(n, light_direction), 0.0);
  float hemisphere = 0.5 + 0.5 * n.y;
  vec3 ambient = mix(vec3(0.25, 0.22, 0.20), vec3(0.45, 0.50, 0.58), hemisphere);
  vec3 c = instance_colour * (ambient + 0.75 * key);
  fragment = vec4(pow(c, vec3(1.0 / 1.1)), 1.0);
}
)";

// The unit box: x and z in [-0.5, 0.5], y in [0, 1]; 12 triangles, a normal per face.
std::vector<glm::vec3> unit_box() {
  std::vector<glm::vec3> out;  // position, normal, interleaved
  const auto face = [&out](glm::vec3 n, glm::vec3 u, glm::vec3 v) {
    const glm::vec3 centre = glm::vec3(0.0f, 0.5f, 0.0f) + 0.5f * n;
    const glm::vec3 corners[4] = {centre - 0.5f * u - 0.5f * v, centre + 0.5f * u - 0.5f * v,
                                  centre + 0.5f * u + 0.5f * v, centre - 0.5f * u + 0.5f * v};
    for (const int k : {0, 1, 2, 0, 2, 3}) {
      out.push_back(corners[k]);
      out.push_back(n);
    }
  };
  // u x v = n for each face, so the triangles wind counter-clockwise seen from outside.
  face({1, 0, 0}, {0, 1, 0}, {0, 0, 1});
  face({-1, 0, 0}, {0, 0, 1}, {0, 1, 0});
  face({0, 1, 0}, {0, 0, 1}, {1, 0, 0});
  face({0, -1, 0}, {1, 0, 0}, {0, 0, 1});
  face({0, 0, 1}, {1, 0, 0}, {0, 1, 0});
  face({0, 0, -1}, {0, 1, 0}, {1, 0, 0});
  return out;
}

}  // namespace

Result<CrowdRenderer> CrowdRenderer::create() {
  CrowdRenderer renderer;
  if (Status s = renderer.build(); !s) return Error{s.message()};
  return renderer;
}

Status CrowdRenderer::build() {
  Result<GLuint> program = link(kVertex, kFragment, "crowd");
  if (!program) return Error{program.message()};
  program_ = *program;

  const std::vector<glm::vec3> box = unit_box();
  vertex_count_ = static_cast<int>(box.size() / 2);
  glGenVertexArrays(1, &vao_);
  glBindVertexArray(vao_);
  glGenBuffers(1, &mesh_);
  glBindBuffer(GL_ARRAY_BUFFER, mesh_);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(box.size() * sizeof(glm::vec3)), box.data(),
               GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 2 * sizeof(glm::vec3), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 2 * sizeof(glm::vec3),
                        reinterpret_cast<void*>(sizeof(glm::vec3)));
  glGenBuffers(1, &instances_);
  glBindBuffer(GL_ARRAY_BUFFER, instances_);
  for (GLuint k = 0; k < 5; ++k) {
    const GLuint location = 2 + k;
    glEnableVertexAttribArray(location);
    glVertexAttribPointer(location, 4, GL_FLOAT, GL_FALSE, sizeof(BoneInstance),
                          reinterpret_cast<void*>(k * sizeof(glm::vec4)));
    glVertexAttribDivisor(location, 1);
  }
  glBindVertexArray(0);
  return Status::success();
}

CrowdRenderer::CrowdRenderer(CrowdRenderer&& other) noexcept {
  *this = std::move(other);
}

CrowdRenderer& CrowdRenderer::operator=(CrowdRenderer&& other) noexcept {
  if (this == &other) return *this;
  release();
  program_ = std::exchange(other.program_, 0);
  vao_ = std::exchange(other.vao_, 0);
  mesh_ = std::exchange(other.mesh_, 0);
  instances_ = std::exchange(other.instances_, 0);
  vertex_count_ = std::exchange(other.vertex_count_, 0);
  return *this;
}

CrowdRenderer::~CrowdRenderer() {
  release();
}

void CrowdRenderer::release() {
  if (program_) glDeleteProgram(program_);
  const GLuint buffers[] = {mesh_, instances_};
  if (vao_) {
    glDeleteBuffers(2, buffers);
    glDeleteVertexArrays(1, &vao_);
  }
  program_ = vao_ = mesh_ = instances_ = 0;
}

void CrowdRenderer::draw(const CameraMatrices& camera, std::span<const BoneInstance> bones) {
  if (bones.empty()) return;
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, instances_);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(bones.size_bytes()), bones.data(),
               GL_STREAM_DRAW);
  glUseProgram(program_);
  const glm::mat4 view_projection = camera.projection * camera.view;
  glUniformMatrix4fv(glGetUniformLocation(program_, "view_projection"), 1, GL_FALSE,
                     glm::value_ptr(view_projection));
  glUniform3fv(glGetUniformLocation(program_, "light_direction"), 1,
               glm::value_ptr(kLightDirection));
  glUniform3fv(glGetUniformLocation(program_, "eye"), 1, glm::value_ptr(camera.eye));
  const GLint flatten = glGetUniformLocation(program_, "flatten");
  const GLint shadow = glGetUniformLocation(program_, "shadow");
  const GLsizei count = static_cast<GLsizei>(bones.size());

  // The shadows: blended, each pixel darkened once (stencil), just above the ground.
  const glm::mat4 flat = shadow_projection(kLightDirection, 0.002f);
  glUniformMatrix4fv(flatten, 1, GL_FALSE, glm::value_ptr(flat));
  glUniform1f(shadow, 1.0f);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glEnable(GL_STENCIL_TEST);
  glStencilFunc(GL_EQUAL, 0, 0xff);
  glStencilOp(GL_KEEP, GL_KEEP, GL_INCR);
  glDepthMask(GL_FALSE);
  glDrawArraysInstanced(GL_TRIANGLES, 0, vertex_count_, count);
  glDepthMask(GL_TRUE);
  glDisable(GL_STENCIL_TEST);
  glDisable(GL_BLEND);

  const glm::mat4 identity(1.0f);
  glUniformMatrix4fv(flatten, 1, GL_FALSE, glm::value_ptr(identity));
  glUniform1f(shadow, 0.0f);
  glEnable(GL_CULL_FACE);
  glDrawArraysInstanced(GL_TRIANGLES, 0, vertex_count_, count);
  glDisable(GL_CULL_FACE);
  glBindVertexArray(0);
}

}  // namespace mm::viewer
