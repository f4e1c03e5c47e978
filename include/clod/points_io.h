#pragma once
// Reading query points from text files, shared by the CLI commands that evaluate something at
// user-given points (`clod closest`, `clod sdf`, `clod normals`).
//
// Format: plain text, whitespace-separated decimal numbers, one point "x y z" per line.
// A line may also hold several points (its number count must then be a multiple of 3).
// Blank lines are skipped; '#' starts a comment that runs to the end of the line.
// Line ends may be LF or CRLF. Numbers use the C locale ("1.5e-3", "-2", "+7"); hexadecimal
// and locale-specific forms are rejected.

#include <filesystem>
#include <string_view>
#include <vector>

#include "clod/math.h"

namespace clod {

/// Parses points from text held in memory (the format above). Returns them in file order;
/// an input without numbers gives an empty vector.
/// Throws clod::Error naming the 1-based line (and the token, when one is at fault):
///  - kParseError: a token that is not a number, or a line whose number count is not a
///    multiple of 3 ("line 4: expected x y z, found 2 numbers");
///  - kNonFiniteVertex: nan, inf, or a number that overflows a double.
/// O(size of the text); never reads past `text`.
std::vector<Vec3> parsePoints(std::string_view text);

/// Reads a points file. Same errors as parsePoints (messages prefixed with the path), plus
/// kFileNotFound, kFileUnreadable, and kEmptyFile for a zero-byte file.
std::vector<Vec3> readPointsFile(const std::filesystem::path& path);

}  // namespace clod
