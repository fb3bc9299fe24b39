#pragma once
// What the bytes of a mesh file are, read before and after a library reader
// (MeshImport.cpp): a file saved under the wrong extension is named for what it
// is, and a reader library's own failure is said in terms of the file.

#include <optional>
#include <string>
#include <string_view>

namespace rotafab::geometry {

// The format the bytes show at a glance ("OBJ", "OFF", "PLY", "glTF",
// "binary glTF", "text STL", "binary"), or "" when they show none.
std::string recognisedContent(std::string_view bytes);

// Why a file with this extension cannot hold these bytes ("the file is text,
// not STL: it looks like OBJ; rename it to .obj"), or nothing.
std::optional<std::string> contentMismatch(std::string_view bytes, const std::string& extension);

// The first face of an OBJ file that refers to a vertex it does not have, with
// its line ("line 8: face 4 refers to vertex 9, but the file has 4 vertices").
std::optional<std::string> objFaceIndexProblem(std::string_view bytes);

// One line for what Assimp's `message` means about the file: no library
// names or data-structure fields, the file's line where that can be found.
std::string explainReaderFailure(std::string_view message, std::string_view bytes, const std::string& extension);

}  // namespace rotafab::geometry
