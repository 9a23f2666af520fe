#pragma once
// Shader programs and the planar shadow, shared by the viewer's renderers (renderer.hpp, the
// character and the level; crowd_renderer.hpp, the crowd's instanced boxes).

#include <glm/glm.hpp>

#include "gl.hpp"
#include "mm/runtime/result.hpp"

namespace mm::viewer {

// The vertex and fragment shaders compiled and linked into a program; an error naming `name`
// (as "renderer: the NAME shader does not compile: " + the driver's log) otherwise.
Result<GLuint> link(const char* vertex, const char* fragment, const char* name);

// Flattens geometry onto the plane y = height along the light direction: the planar shadow.
glm::mat4 shadow_projection(const glm::vec3& light, float height);

}  // namespace mm::viewer
