#pragma once
// The test course: a level of the shapes a character must handle, laid out in lanes side by side
// along +Z on a flat ground, written as a .glb by mm-make-course (world/tools/make_course.cpp)
// and shipped as data/levels/course.glb. tests/world/course_test.cpp regenerates it and checks
// the shipped file is byte for byte what this code writes, so it is never edited by hand.
//
// Every part is one node (named as in course_parts()) under a root node "course", with its mesh
// in the part's own frame and the node's translation (and rotation, for the turned wall)
// placing it. docs/world-levels.md holds the table course_table() prints.

#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace mm {

// One part of the course, as the table gives it (world frame, metres).
struct CoursePart {
  std::string name;
  glm::dvec2 x_range{0.0};  // the part's extent in x (min, max)
  glm::dvec2 z_range{0.0};  // and in z
  double top = 0.0;         // the highest point of its surface
  std::string what;         // its shape and how to walk across it
};

// The parts in lane order (+X), the ground first.
std::vector<CoursePart> course_parts();

// The course as a markdown table: part, x range, z range, top, what it is.
std::string course_table();

// The course's .glb bytes: the same on every run and machine (tinygltf's writer, positions
// computed in double and rounded to float once).
std::vector<unsigned char> course_glb();

// The height of the course's surface at world (x, z): the top of whatever part is there, else the
// ground (0); on the rough patch, its mesh's own surface (the height field at the 10 cm grid's
// vertices, linear across each triangle). For scripts and tests that walk across the course.
double course_height(double x, double z);

// The second course (data/levels/course2.glb, world/src/course2.cpp, `mm-make-course --course 2`):
// the same kinds of shapes with other numbers, and more (a ramp and stairs met from their top, a
// wall at 45° and at 60°, a concave corner, a 1 m corridor, a kerb, a slope walked across), for
// measuring what was tuned on the first. Its root node is "course2"; the functions are the
// first course's.
std::vector<CoursePart> course2_parts();
std::string course2_table();
std::vector<unsigned char> course2_glb();
double course2_height(double x, double z);

// Any course's parts as the markdown table above.
std::string course_table_of(const std::vector<CoursePart>& parts);

}  // namespace mm
