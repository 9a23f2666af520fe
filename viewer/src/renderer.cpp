#include "renderer.hpp"

#include <string>
#include <utility>
#include <vector>

#include <glm/gtc/type_ptr.hpp>

#include "gl.hpp"
#include "gl_program.hpp"

namespace mm::viewer {
namespace {

const glm::vec3 kSky{0.80f, 0.85f, 0.90f};
// The key light comes from above, in front and to the side, so the shadow falls behind-left
// of the character and the feet's contact with the ground stays visible.
const glm::vec3 kLightDirection = glm::normalize(glm::vec3(0.4f, 1.0f, 0.55f));

const char* const kMeshVertex = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
uniform mat4 view_projection;
uniform mat4 model;
out vec3 world_normal;
out vec3 world_position;
void main() {
  vec4 p = model * vec4(position, 1.0);
  world_position = p.xyz;
  world_normal = normal;
  gl_Position = view_projection * p;
}
)";

const char* const kMeshFragment = R"(#version 330 core
in vec3 world_normal;
in vec3 world_position;
uniform vec3 colour;
uniform vec3 light_direction;
uniform vec3 eye;
uniform float shadow;  // 1: draw flat dark (the projected shadow)
out vec4 fragment;
void main() {
  if (shadow > 0.5) { fragment = vec4(0.0, 0.0, 0.0, 0.35); return; }
  vec3 n = normalize(world_normal);
  vec3 v = normalize(eye - world_position);
  float key = max(dot(n, light_direction), 0.0);
  float hemisphere = 0.5 + 0.5 * n.y;
  vec3 ambient = mix(vec3(0.25, 0.22, 0.20), vec3(0.45, 0.50, 0.58), hemisphere);
  float rim = pow(1.0 - max(dot(n, v), 0.0), 3.0) * 0.25;
  vec3 h = normalize(light_direction + v);
  float specular = pow(max(dot(n, h), 0.0), 32.0) * 0.15;
  vec3 c = colour * (ambient + 0.75 * key) + vec3(rim + specular);
  fragment = vec4(pow(c, vec3(1.0 / 1.1)), 1.0);
}
)";

const char* const kGroundVertex = R"(#version 330 core
layout(location = 0) in vec2 corner;
uniform mat4 view_projection;
uniform vec3 focus;
uniform float extent;
out vec3 world_position;
void main() {
  world_position = vec3(focus.x + corner.x * extent, 0.0, focus.z + corner.y * extent);
  gl_Position = view_projection * vec4(world_position, 1.0);
}
)";

// Anti-aliased grid lines from screen-space derivatives: thin every 0.5 m, thicker every 1 m,
// the world axes tinted; the grid fades out with distance into the sky colour.
const char* const kGroundFragment = R"(#version 330 core
in vec3 world_position;
uniform vec3 eye;
uniform vec3 sky;
out vec4 fragment;
float grid(vec2 p, float spacing, float width) {
  vec2 g = p / spacing;
  vec2 d = abs(fract(g - 0.5) - 0.5) / fwidth(g);
  return 1.0 - clamp(min(d.x, d.y) - width, 0.0, 1.0);
}
void main() {
  vec2 p = world_position.xz;
  vec3 c = vec3(0.62, 0.62, 0.60);
  c = mix(c, vec3(0.55, 0.55, 0.54), grid(p, 0.5, 0.0));
  c = mix(c, vec3(0.42, 0.42, 0.42), grid(p, 1.0, 0.0));
  vec2 axis = abs(p) / fwidth(p);
  c = mix(c, vec3(0.70, 0.25, 0.25), 1.0 - clamp(axis.y - 1.0, 0.0, 1.0));
  c = mix(c, vec3(0.25, 0.35, 0.75), 1.0 - clamp(axis.x - 1.0, 0.0, 1.0));
  float distance = length(world_position - eye);
  c = mix(c, sky, smoothstep(15.0, 45.0, distance));
  fragment = vec4(c, 1.0);
}
)";

const char* const kLineVertex = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 colour;
uniform mat4 view_projection;
out vec3 line_colour;
void main() {
  line_colour = colour;
  gl_Position = view_projection * vec4(position, 1.0);
}
)";

const char* const kLineFragment = R"(#version 330 core
in vec3 line_colour;
out vec4 fragment;
void main() { fragment = vec4(line_colour, 1.0); }
)";

GLint uniform(GLuint program, const char* name) {
  return glGetUniformLocation(program, name);
}

void set_matrix(GLuint program, const char* name, const glm::mat4& m) {
  glUniformMatrix4fv(uniform(program, name), 1, GL_FALSE, glm::value_ptr(m));
}

void set_vec3(GLuint program, const char* name, const glm::vec3& v) {
  glUniform3fv(uniform(program, name), 1, glm::value_ptr(v));
}

}  // namespace

Result<Renderer> Renderer::create() {
  Renderer renderer;
  if (Status s = renderer.build(); !s) return Error{s.message()};
  return renderer;
}

Status Renderer::build() {
  Result<GLuint> mesh = link(kMeshVertex, kMeshFragment, "mesh");
  if (!mesh) return Error{mesh.message()};
  mesh_program_ = *mesh;
  Result<GLuint> ground = link(kGroundVertex, kGroundFragment, "ground");
  if (!ground) return Error{ground.message()};
  ground_program_ = *ground;
  Result<GLuint> lines = link(kLineVertex, kLineFragment, "line");
  if (!lines) return Error{lines.message()};
  line_program_ = *lines;

  glGenVertexArrays(1, &body_vao_);
  glBindVertexArray(body_vao_);
  glGenBuffers(1, &body_positions_);
  glBindBuffer(GL_ARRAY_BUFFER, body_positions_);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(glm::vec3), nullptr);
  glGenBuffers(1, &body_normals_);
  glBindBuffer(GL_ARRAY_BUFFER, body_normals_);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(glm::vec3), nullptr);
  glGenBuffers(1, &body_indices_);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, body_indices_);

  const float corners[] = {-1, -1, 1, -1, 1, 1, -1, -1, 1, 1, -1, 1};
  glGenVertexArrays(1, &ground_vao_);
  glBindVertexArray(ground_vao_);
  glGenBuffers(1, &ground_vbo_);
  glBindBuffer(GL_ARRAY_BUFFER, ground_vbo_);
  glBufferData(GL_ARRAY_BUFFER, sizeof corners, corners, GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 2 * sizeof(float), nullptr);

  // The level: positions and flat normals interleaved, three vertices a triangle.
  glGenVertexArrays(1, &level_vao_);
  glBindVertexArray(level_vao_);
  glGenBuffers(1, &level_vbo_);
  glBindBuffer(GL_ARRAY_BUFFER, level_vbo_);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 2 * sizeof(glm::vec3), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 2 * sizeof(glm::vec3),
                        reinterpret_cast<void*>(sizeof(glm::vec3)));

  glGenVertexArrays(1, &line_vao_);
  glBindVertexArray(line_vao_);
  glGenBuffers(1, &line_vbo_);
  glBindBuffer(GL_ARRAY_BUFFER, line_vbo_);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(LineVertex), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(LineVertex),
                        reinterpret_cast<void*>(offsetof(LineVertex, colour)));
  glBindVertexArray(0);
  return Status::success();
}

Renderer::Renderer(Renderer&& other) noexcept {
  *this = std::move(other);
}

Renderer& Renderer::operator=(Renderer&& other) noexcept {
  if (this == &other) return *this;
  release();
  mesh_program_ = std::exchange(other.mesh_program_, 0);
  ground_program_ = std::exchange(other.ground_program_, 0);
  line_program_ = std::exchange(other.line_program_, 0);
  body_vao_ = std::exchange(other.body_vao_, 0);
  body_positions_ = std::exchange(other.body_positions_, 0);
  body_normals_ = std::exchange(other.body_normals_, 0);
  body_indices_ = std::exchange(other.body_indices_, 0);
  ground_vao_ = std::exchange(other.ground_vao_, 0);
  ground_vbo_ = std::exchange(other.ground_vbo_, 0);
  line_vao_ = std::exchange(other.line_vao_, 0);
  line_vbo_ = std::exchange(other.line_vbo_, 0);
  level_vao_ = std::exchange(other.level_vao_, 0);
  level_vbo_ = std::exchange(other.level_vbo_, 0);
  body_index_count_ = std::exchange(other.body_index_count_, 0);
  level_vertex_count_ = std::exchange(other.level_vertex_count_, 0);
  return *this;
}

Renderer::~Renderer() {
  release();
}

void Renderer::release() {
  // Zero names are silently ignored by glDelete*, so a moved-from renderer frees nothing.
  for (GLuint program : {mesh_program_, ground_program_, line_program_}) {
    if (program) glDeleteProgram(program);
  }
  const GLuint buffers[] = {body_positions_, body_normals_, body_indices_,
                            ground_vbo_,     line_vbo_,     level_vbo_};
  const GLuint arrays[] = {body_vao_, ground_vao_, line_vao_, level_vao_};
  if (mesh_program_) {
    glDeleteBuffers(6, buffers);
    glDeleteVertexArrays(4, arrays);
  }
  mesh_program_ = ground_program_ = line_program_ = 0;
}

void Renderer::set_body_triangles(std::span<const uint32_t> indices) {
  glBindVertexArray(body_vao_);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, body_indices_);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(indices.size_bytes()),
               indices.data(), GL_STATIC_DRAW);
  glBindVertexArray(0);
  body_index_count_ = static_cast<int>(indices.size());
}

void Renderer::set_level(std::span<const glm::vec3> positions, std::span<const uint32_t> indices) {
  std::vector<glm::vec3> vertices;
  vertices.reserve(indices.size() * 2);
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    const glm::vec3& a = positions[indices[t]];
    const glm::vec3& b = positions[indices[t + 1]];
    const glm::vec3& c = positions[indices[t + 2]];
    glm::vec3 normal = glm::cross(b - a, c - a);
    const float length = glm::length(normal);
    normal = length > 0.0f ? normal / length : glm::vec3(0.0f, 1.0f, 0.0f);
    for (const glm::vec3* p : {&a, &b, &c}) {
      vertices.push_back(*p);
      vertices.push_back(normal);
    }
  }
  glBindVertexArray(level_vao_);
  glBindBuffer(GL_ARRAY_BUFFER, level_vbo_);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(glm::vec3)),
               vertices.data(), GL_STATIC_DRAW);
  glBindVertexArray(0);
  level_vertex_count_ = static_cast<int>(vertices.size() / 2);
}

void Renderer::draw_level(const CameraMatrices& camera) {
  if (level_vertex_count_ == 0) return;
  glUseProgram(mesh_program_);
  set_matrix(mesh_program_, "view_projection", camera.projection * camera.view);
  set_matrix(mesh_program_, "model", glm::mat4(1.0f));
  set_vec3(mesh_program_, "light_direction", kLightDirection);
  set_vec3(mesh_program_, "eye", camera.eye);
  set_vec3(mesh_program_, "colour", glm::vec3(0.62f, 0.60f, 0.56f));
  glUniform1f(uniform(mesh_program_, "shadow"), 0.0f);
  glBindVertexArray(level_vao_);
  glDrawArrays(GL_TRIANGLES, 0, level_vertex_count_);
  glBindVertexArray(0);
}

void Renderer::begin(unsigned framebuffer, int width, int height) {
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  glViewport(0, 0, width, height);
  glClearColor(kSky.r, kSky.g, kSky.b, 1.0f);
  glClearStencil(0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glEnable(GL_MULTISAMPLE);
}

void Renderer::draw_ground(const CameraMatrices& camera, const glm::vec3& focus) {
  glUseProgram(ground_program_);
  set_matrix(ground_program_, "view_projection", camera.projection * camera.view);
  set_vec3(ground_program_, "focus", focus);
  set_vec3(ground_program_, "eye", camera.eye);
  set_vec3(ground_program_, "sky", kSky);
  glUniform1f(uniform(ground_program_, "extent"), 60.0f);
  glBindVertexArray(ground_vao_);
  glDrawArrays(GL_TRIANGLES, 0, 6);
}

void Renderer::draw_body(const CameraMatrices& camera, std::span<const glm::vec3> positions,
                         std::span<const glm::vec3> normals, const glm::vec3& colour,
                         float ground_height) {
  if (body_index_count_ == 0 || positions.empty()) return;
  glBindVertexArray(body_vao_);
  glBindBuffer(GL_ARRAY_BUFFER, body_positions_);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(positions.size_bytes()), positions.data(),
               GL_STREAM_DRAW);
  glBindBuffer(GL_ARRAY_BUFFER, body_normals_);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(normals.size_bytes()), normals.data(),
               GL_STREAM_DRAW);
  glUseProgram(mesh_program_);
  set_matrix(mesh_program_, "view_projection", camera.projection * camera.view);
  set_vec3(mesh_program_, "light_direction", kLightDirection);
  set_vec3(mesh_program_, "eye", camera.eye);
  set_vec3(mesh_program_, "colour", colour);

  // The shadow first: flattened, blended, and each pixel darkened once (stencil), just above
  // the ground so it does not fight the ground's depth.
  set_matrix(mesh_program_, "model", shadow_projection(kLightDirection, ground_height + 0.002f));
  glUniform1f(uniform(mesh_program_, "shadow"), 1.0f);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glEnable(GL_STENCIL_TEST);
  glStencilFunc(GL_EQUAL, 0, 0xff);
  glStencilOp(GL_KEEP, GL_KEEP, GL_INCR);
  glDepthMask(GL_FALSE);
  glDrawElements(GL_TRIANGLES, body_index_count_, GL_UNSIGNED_INT, nullptr);
  glDepthMask(GL_TRUE);
  glDisable(GL_STENCIL_TEST);
  glDisable(GL_BLEND);

  set_matrix(mesh_program_, "model", glm::mat4(1.0f));
  glUniform1f(uniform(mesh_program_, "shadow"), 0.0f);
  glEnable(GL_CULL_FACE);
  glDrawElements(GL_TRIANGLES, body_index_count_, GL_UNSIGNED_INT, nullptr);
  glDisable(GL_CULL_FACE);
  glBindVertexArray(0);
}

void Renderer::draw_lines(const CameraMatrices& camera, const DebugLines& lines, bool over_scene) {
  const auto& vertices = lines.vertices();
  if (vertices.empty()) return;
  glBindVertexArray(line_vao_);
  glBindBuffer(GL_ARRAY_BUFFER, line_vbo_);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(LineVertex)),
               vertices.data(), GL_STREAM_DRAW);
  glUseProgram(line_program_);
  set_matrix(line_program_, "view_projection", camera.projection * camera.view);
  if (over_scene) glDisable(GL_DEPTH_TEST);
  glDrawArrays(GL_LINES, 0, static_cast<GLsizei>(vertices.size()));
  if (over_scene) glEnable(GL_DEPTH_TEST);
  glBindVertexArray(0);
}

}  // namespace mm::viewer
