#pragma once
// Typed arrays written into a glTF model's one buffer, for the writers of glTF files: the
// exporter (gltf.cpp) and the generated test courses (world/src/course_mesh.cpp, which reaches
// this internal header as it does gltf_files.hpp). Not installed.

#include <tiny_gltf.h>

#include <cstddef>
#include <utility>
#include <vector>

namespace mm::gltf_export {

// Appends typed arrays to one buffer, each in its own 4-byte aligned buffer view.
class BufferWriter {
 public:
  explicit BufferWriter(tinygltf::Model& model) : model_(model) {}

  int add(const void* data, size_t bytes, int component_type, int type, size_t count, int target,
          std::vector<double> min = {}, std::vector<double> max = {}) {
    while (bytes_.size() % 4 != 0) bytes_.push_back(0);
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = bytes_.size();
    view.byteLength = bytes;
    view.target = target;
    const auto* p = static_cast<const unsigned char*>(data);
    bytes_.insert(bytes_.end(), p, p + bytes);
    model_.bufferViews.push_back(std::move(view));

    tinygltf::Accessor accessor;
    accessor.sparse = {};
    accessor.bufferView = static_cast<int>(model_.bufferViews.size() - 1);
    accessor.byteOffset = 0;
    accessor.componentType = component_type;
    accessor.type = type;
    accessor.count = count;
    accessor.minValues = std::move(min);
    accessor.maxValues = std::move(max);
    model_.accessors.push_back(std::move(accessor));
    return static_cast<int>(model_.accessors.size() - 1);
  }

  void finish() {
    while (bytes_.size() % 4 != 0) bytes_.push_back(0);
    tinygltf::Buffer buffer;
    buffer.data = std::move(bytes_);
    model_.buffers.push_back(std::move(buffer));
  }

 private:
  tinygltf::Model& model_;
  std::vector<unsigned char> bytes_;
};

}  // namespace mm::gltf_export
