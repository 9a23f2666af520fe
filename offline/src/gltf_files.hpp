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
#include <span>
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

// ---- What the glTF importer (gltf.cpp) and the level reader (world/src/level.cpp) share about
// a file's structure.

// Components per element of an accessor type (TINYGLTF_TYPE_*); 0 for an unknown type.
int components_in_type(int type);
// "VEC3", or "unknown type (N)".
std::string type_name(int type);
// Bytes per component of the component types glTF 2.0 allows in accessors (INT and DOUBLE are not
// allowed): 0 for any other.
int component_size(int component_type);
// "FLOAT", or "unknown component type (N)".
std::string component_name(int component_type);

// Checks the GLB container (header, chunk lengths) before tinygltf sees it, so no length field
// can make anything read past the end of the bytes. Returns the total length to parse.
Result<size_t> check_glb_container(std::span<const unsigned char> bytes);
// The length of the JSON chunk of a GLB that check_glb_container accepted (it starts at byte 20).
size_t glb_json_chunk_length(std::span<const unsigned char> bytes);

// The file's JSON and buffers as tinygltf reads them (`bytes`: a .gltf's text or a .glb's
// container), after the container (check_glb_container) and every file a buffer names
// (read_external_buffers, refused unless allow_external_files) are checked; images are not
// decoded. `path` is where the bytes came from: its folder is where buffers' files are looked
// for, and a ".glb" name must hold binary glTF. The messages say what is wrong, without the file
// name (the caller adds it).
Result<tinygltf::Model> load_model(std::span<const unsigned char> bytes,
                                   const std::filesystem::path& path, bool allow_external_files);

// A tinygltf image loader that decodes nothing: images are never needed, and textured files
// still load.
bool skip_image(tinygltf::Image*, const int, std::string*, std::string*, int, int,
                const unsigned char*, int, void*);

}  // namespace mm::gltf_files
