/// @file data_path.cpp
/// @brief Where the source models are found.

#include <kdet/error.hpp>
#include <kdet/prepare.hpp>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>

namespace kdet {

std::string data_dir() {
    const char* dir = std::getenv("KDET_DATA_DIR");
    return (dir != nullptr && *dir != '\0') ? std::string(dir) : std::string("../shared/models");
}

std::string data_path(const std::string& file) {
    const std::string dir = data_dir();
    const std::string path = (std::filesystem::path(dir) / file).string();
    std::error_code ignored;
    if (!std::filesystem::is_regular_file(path, ignored)) {
        throw Error("model '" + file + "' not found in " + dir +
                    " (set KDET_DATA_DIR to the folder holding the models)");
    }
    return path;
}

} // namespace kdet
