#pragma once
/// @file png_file.hpp
/// @brief Writing pictures as PNG files (libpng).

#include <cstdint>
#include <string>
#include <vector>

namespace kdet::view {

/// @brief Writes @p rgb (rows from the top, 3 bytes per pixel) as an 8-bit RGB PNG. Throws
/// kdet::Error naming the file when it cannot be written.
void write_png(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgb);

} // namespace kdet::view
