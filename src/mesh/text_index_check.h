#pragma once
// Checks on the raw text of OBJ and PLY files, run next to Assimp because Assimp either rejects
// an out-of-range index without saying where (OBJ: "vertex index out of range") or never
// returns (PLY: a header without an `end_header` line loops forever in Assimp 5.2.5).
// (OFF is not read by Assimp at all: see off_reader.h.) The binary glTF header check lives here
// too: Assimp allocates and clears whatever chunk length a GLB header claims (1 GiB for a
// 788-byte file found by fuzz_mesh_load) before it notices the file is shorter. Collada too: a
// letter in a number list (`<p>0 4 x 2</p>`) makes Assimp's Collada reader spin forever.
// These scanners read only what they need; they are not loaders, and on anything they do not
// understand they return std::nullopt and leave the verdict to Assimp.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace clod::detail {

/// First face/line/point index of an OBJ text that refers to a vertex that does not exist
/// (positive index > number of `v` lines in the file, negative index reaching before the first
/// vertex, or 0), as a message naming the line; nullopt when none. O(size).
std::optional<std::string> findBadObjIndex(std::string_view text);

/// True when the bytes start (after whitespace and NUL bytes, which Assimp drops) with the PLY
/// magic "ply", case-insensitive:
/// Assimp hands such content to its PLY reader whatever the extension says.
bool looksLikePly(std::string_view text);

/// For PLY content (looksLikePly), a message when the header has no line reading exactly
/// `end_header` (trailing spaces and CR allowed), which would hang Assimp's PLY reader; nullopt
/// otherwise. O(size).
std::optional<std::string> findPlyHeaderProblem(std::string_view text);

/// True when the bytes start with the GLB magic "glTF".
bool looksLikeGlb(std::string_view bytes);

/// For GLB content (looksLikeGlb), a message when the declared total length or a chunk length
/// does not fit in the bytes actually there; nullopt otherwise. O(number of chunks).
std::optional<std::string> findGlbHeaderProblem(std::string_view bytes);

/// True when the first character after whitespace (and a UTF-8 byte order mark) is '{': the
/// start of a .gltf document, which Assimp recognises by content whatever the extension.
bool looksLikeJson(std::string_view text);

/// The JSON chunk of GLB content whose header findGlbHeaderProblem accepted (the first chunk,
/// type "JSON"); nullopt when there is none. O(1).
std::optional<std::string_view> glbJsonChunk(std::string_view bytes);

/// A message when JSON text nests arrays/objects more than `maxDepth` deep, naming the byte
/// where it does; nullopt otherwise. Assimp's glTF reader parses JSON recursively, so deep
/// nesting overflows the stack (200,000 '[' in a 400 kB .gltf crashed `clod inspect`).
/// A linear scan counting '[' and '{' outside strings: it does not validate the JSON. O(size).
std::optional<std::string> findJsonDepthProblem(std::string_view json, std::uint32_t maxDepth);

/// True when the text holds a `<COLLADA` element (Assimp recognises Collada by content).
bool looksLikeCollada(std::string_view text);

/// For Collada content, a message when a number list -- the contents of `<p>`, `<vcount>`,
/// `<v>`, `<h>`, `<int_array>` or `<float_array>` -- holds a character no number of the list is
/// written with (digits, whitespace, '-'; in `<float_array>` also '+', '.', 'e', 'E'), naming
/// the element and the byte; nullopt
/// otherwise. Assimp 5.2.5's Collada reader never returns on such a list (fuzz_mesh_load:
/// one byte of box_z_up.dae's `<p>` changed). Also a message when an `<int_array>` or
/// `<float_array>` has no `count` attribute, or one that is not the number of values it holds
/// (0 included): Assimp sizes the array by it, and an accessor reading an array sized 0 crashed
/// (fuzz_mesh_load: `count` misspelt). O(size).
std::optional<std::string> findColladaNumberListProblem(std::string_view text);

}  // namespace clod::detail
