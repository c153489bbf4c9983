#pragma once
/// @file error.hpp
/// @brief The one exception type kdet throws on the host.

#include <stdexcept>
#include <string>

namespace kdet {

/// @brief Thrown for bad input (files, indices, coordinates, options) and for unsupported requests.
/// The message is a single line; file errors start with "path:line: ".
class Error : public std::runtime_error {
public:
    explicit Error(const std::string& message) : std::runtime_error(message) {}
};

} // namespace kdet
