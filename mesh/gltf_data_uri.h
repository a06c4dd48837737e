#pragma once
// glTF data URIs ("data:<media type>;base64,<payload>"): the strict check tinygltf leaves out (its decoder stops
// at the first character outside the base64 alphabet and keeps what it has), and short messages about them
// (tinygltf's errors quote the whole URI, which can be megabytes long).
#include <cstddef>
#include <string>
#include <string_view>

namespace hemibake {

// "" when `uri` is a well-formed base64 data URI, else the problem in a few words ("is not valid base64: character
// '!' at position 20 of its data"). `decodedBytes`, when given, receives the payload's decoded size.
std::string dataUriProblem(std::string_view uri, std::size_t* decodedBytes = nullptr);

// `text` with the payload of every data URI in it replaced by "…(N characters)".
std::string elideDataUris(const std::string& text);

}  // namespace hemibake
