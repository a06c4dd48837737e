#pragma once
// OpenImageIO reports errors through per-object and global strings with trailing newlines; this makes them
// one line for InputError/runtime_error messages.
#include <string>

#include <OpenImageIO/imageio.h>

namespace hemibake {

inline std::string oiioError(const std::string& specific) {
    std::string message = specific.empty() ? OIIO::geterror() : specific;
    while (!message.empty() && (message.back() == '\n' || message.back() == '\r')) message.pop_back();
    return message.empty() ? "unknown OpenImageIO error" : message;
}

}  // namespace hemibake
