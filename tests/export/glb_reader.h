#pragma once
// A GLB reader written for the tests from the glTF 2.0 specification (section 4.4, "GLB File
// Format Specification"), independent of the writer and of TinyGLTF: 12-byte header ("glTF",
// version 2, total length), then chunks of (u32 length, u32 type, data) with the JSON chunk
// first and an optional BIN chunk. It throws std::runtime_error on anything malformed, so a test
// that reads a file also checks its framing. Used by tests/export and tests/cli/export_test.cpp.
#include <cstdint>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace clod::test {

struct Glb {
  nlohmann::json json;
  std::vector<unsigned char> bin;
  std::uint32_t jsonChunkLength = 0, binChunkLength = 0;
};

inline std::uint32_t readU32(const std::string& bytes, std::size_t at) {
  if (at + 4 > bytes.size()) throw std::runtime_error("GLB: read past the end at " + std::to_string(at));
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = v << 8 | static_cast<unsigned char>(bytes[at + std::size_t(i)]);  // little-endian
  return v;
}

inline Glb parseGlb(const std::string& bytes) {
  Glb glb;
  if (bytes.size() < 20 || bytes.compare(0, 4, "glTF") != 0) throw std::runtime_error("GLB: bad magic");
  if (readU32(bytes, 4) != 2) throw std::runtime_error("GLB: version is not 2");
  if (readU32(bytes, 8) != bytes.size()) throw std::runtime_error("GLB: header length != file size");
  std::size_t at = 12;
  int chunk = 0;
  while (at < bytes.size()) {
    const std::uint32_t length = readU32(bytes, at), type = readU32(bytes, at + 4);
    if (length % 4 != 0) throw std::runtime_error("GLB: chunk length not a multiple of 4");
    if (at + 8 + length > bytes.size()) throw std::runtime_error("GLB: chunk runs past the end");
    const std::string data = bytes.substr(at + 8, length);
    if (chunk == 0) {
      if (type != 0x4E4F534Au) throw std::runtime_error("GLB: first chunk is not JSON");
      glb.json = nlohmann::json::parse(data);  // trailing spaces (padding) are allowed JSON whitespace
      glb.jsonChunkLength = length;
    } else if (chunk == 1) {
      if (type != 0x004E4942u) throw std::runtime_error("GLB: second chunk is not BIN");
      glb.bin.assign(data.begin(), data.end());
      glb.binChunkLength = length;
    }
    at += 8 + length;
    ++chunk;
  }
  return glb;
}

/// The values of a float or uint32 accessor (tightly packed, as the exporter writes), as doubles.
inline std::vector<double> accessorValues(const Glb& glb, int accessorIndex) {
  const nlohmann::json& a = glb.json.at("accessors").at(accessorIndex);
  const nlohmann::json& view = glb.json.at("bufferViews").at(a.at("bufferView").get<int>());
  static const std::map<std::string, int> kComponents = {{"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4}, {"MAT4", 16}};
  const int components = kComponents.at(a.at("type").get<std::string>());
  const std::size_t count = a.at("count").get<std::size_t>() * std::size_t(components);
  const std::size_t start = view.value("byteOffset", std::size_t(0)) + a.value("byteOffset", std::size_t(0));
  if (view.contains("byteStride") && view["byteStride"].get<int>() != components * 4)
    throw std::runtime_error("GLB: strided views are not expected");
  if (start + 4 * count > glb.bin.size()) throw std::runtime_error("GLB: accessor runs past the BIN chunk");
  std::vector<double> out(count);
  const int type = a.at("componentType").get<int>();
  for (std::size_t i = 0; i < count; ++i) {
    std::uint32_t raw;
    std::memcpy(&raw, glb.bin.data() + start + 4 * i, 4);
    if (type == 5126) {
      float f;
      std::memcpy(&f, &raw, 4);
      out[i] = f;
    } else if (type == 5125) {
      out[i] = raw;
    } else {
      throw std::runtime_error("GLB: unexpected componentType " + std::to_string(type));
    }
  }
  return out;
}

}  // namespace clod::test
