#pragma once
// Which files a glTF file may make the importer read, and the file-system callbacks that keep
// tinygltf to them. Internal to the glTF importer (gltf.cpp); the rules are documented in
// mm/offline/gltf.hpp.
//
// The buffers' uris are checked before tinygltf runs, on the JSON alone, and the files that
// pass are read here. tinygltf then gets callbacks that serve those bytes and open nothing:
// whatever else a file names (an image, a uri this check did not see) is "not found" to it.

#include <tiny_gltf.h>

#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "mm/runtime/result.hpp"

namespace mm::gltf_files {

// The bytes of the external files a glTF file's buffers name, keyed by the uri as tinygltf
// asks for it (percent-decoded), each with the number of buffers still to be served it.
struct ExternalFiles {
  struct File {
    std::vector<unsigned char> bytes;
    int readers = 0;
  };
  std::map<std::string, File> files;
};

// Checks the uri of every buffer in the glTF JSON `json` (a .gltf file, or a GLB's JSON chunk)
// and reads the files that pass. `folder` is the glTF file's folder; with allow_files false,
// every uri that is not a data: URI is refused. Errors name the buffer (index and uri) and
// the reason. JSON that does not parse yields no files (tinygltf then reports the syntax).
Result<ExternalFiles> read_external_buffers(std::string_view json,
                                            const std::filesystem::path& folder, bool allow_files);

// Callbacks under which tinygltf reads `files` and nothing else; `files` must outlive the load.
tinygltf::FsCallbacks confined_callbacks(ExternalFiles& files);

}  // namespace mm::gltf_files
