// mm-make-course: writes a test course (mm/world/course.hpp) as a .glb and prints the table of
// its parts (the one in docs/world-levels.md). The shipped files are data/levels/course.glb and
// course2.glb:
//   build/release/world/mm-make-course data/levels/course.glb
//   build/release/world/mm-make-course --course 2 data/levels/course2.glb
// Exit status as the project's programs (programs/command_line.hpp): 0 fine or --help, 1 the file
// cannot be written, 2 bad usage. CLI11 directly: the course needs none of mm_programs.

#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "mm/database/files.hpp"
#include "mm/world/course.hpp"

int main(int argc, char** argv) {
  CLI::App app{"Writes the test course as a .glb and prints the table of its parts"};
  std::string out;
  int course = 1;
  app.add_option("out", out, "the .glb to write (the shipped one: data/levels/course.glb)")
      ->required();
  app.add_option("--course", course,
                 "which course: 1 (data/levels/course.glb) or 2 (data/levels/course2.glb)")
      ->check(CLI::IsMember({1, 2}));
  app.footer("exit status: 0 fine, 1 the file cannot be written, 2 bad usage");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // CLI11's own codes say which usage error it was; the project's programs all say 2.
    return app.exit(e) == 0 ? 0 : 2;
  }

  const std::vector<unsigned char> bytes = course == 2 ? mm::course2_glb() : mm::course_glb();
  const mm::Status written = mm::write_whole_file(
      out, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), "course");
  if (!written) {
    std::fprintf(stderr, "mm-make-course: %s\n", written.message().c_str());
    return 1;
  }
  const std::string table = course == 2 ? mm::course2_table() : mm::course_table();
  std::printf("%s\nwrote %s (%zu bytes)\n", table.c_str(), out.c_str(), bytes.size());
  return 0;
}
