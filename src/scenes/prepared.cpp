/// @file prepared.cpp
/// @brief The thesis models and the cache of prepared meshes (read side; `kdet prepare` writes it).

#include <kdet/error.hpp>
#include <kdet/io.hpp>
#include <kdet/prepare.hpp>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <system_error>
#include <unistd.h>

namespace kdet {
namespace {

constexpr const char* kRecordHeader = "kdet-prepared 1";

std::string record_error(const std::string& path, std::size_t line, const std::string& what) {
    return path + ":" + std::to_string(line) + ": " + what;
}

} // namespace

const std::vector<ModelInfo>& thesis_models() {
    static const std::vector<ModelInfo> models = {
        {"armadillo", "armadillo.obj", {10121, 20052, 49218, 83804}},
        {"happy-buddha", "happy-buddha.off", {10433, 28584, 49616, 87158}},
        {"max-planck", "max-planck.obj", {10093, 21240, 43648, 92387}},
        {"bunny", "stanford-bunny.obj", {10308, 29274, 56924, 99201}},
    };
    return models;
}

const ModelInfo& thesis_model(const std::string& name) {
    std::string known;
    for (const ModelInfo& model : thesis_models()) {
        if (model.name == name) return model;
        known += (known.empty() ? "" : ", ") + model.name;
    }
    throw Error("unknown model '" + name + "' (known models: " + known + ")");
}

std::size_t target_tets(const std::string& model, int resolution) {
    const ModelInfo& info = thesis_model(model);
    if (resolution < 1 || resolution > 4)
        throw Error("resolution " + std::to_string(resolution) + " of model " + model + " is not 1, 2, 3 or 4");
    return info.target_tets[static_cast<std::size_t>(resolution - 1)];
}

std::string cache_dir() {
    const auto set = [](const char* name) {
        const char* value = std::getenv(name);
        return value != nullptr && *value != '\0' ? std::string(value) : std::string();
    };
    if (std::string dir = set("KDET_CACHE_DIR"); !dir.empty()) return dir;
    if (std::string xdg = set("XDG_CACHE_HOME"); !xdg.empty()) return (std::filesystem::path(xdg) / "kdet").string();
    if (std::string home = set("HOME"); !home.empty())
        return (std::filesystem::path(home) / ".cache" / "kdet").string();
    throw Error("no cache folder: set KDET_CACHE_DIR (or HOME)");
}

std::string prepared_record_path(const std::string& model, int resolution) {
    return (std::filesystem::path(cache_dir()) / (model + "-r" + std::to_string(resolution) + ".txt")).string();
}

std::string prepared_mesh_stem(const std::string& key) {
    return (std::filesystem::path(cache_dir()) / "meshes" / key).string();
}

PreparedRecord read_prepared_record(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw Error(path + ": cannot open file");
    PreparedRecord record;
    std::string line;
    std::size_t number = 0;
    bool header = false;
    while (std::getline(in, line)) {
        ++number;
        if (!header) {
            if (line != kRecordHeader) throw Error(record_error(path, number, std::string("expected '") + kRecordHeader + "'"));
            header = true;
            continue;
        }
        std::istringstream words(line);
        std::string field;
        if (!(words >> field)) continue;
        bool ok = true;
        if (field == "model") ok = static_cast<bool>(words >> record.model);
        else if (field == "resolution") ok = static_cast<bool>(words >> record.resolution);
        else if (field == "source_hash") ok = static_cast<bool>(words >> record.source_hash);
        else if (field == "key") ok = static_cast<bool>(words >> record.key);
        else if (field == "tets") ok = static_cast<bool>(words >> record.tets);
        else if (field == "alpha") ok = static_cast<bool>(words >> record.alpha);
        else if (field == "seconds") ok = static_cast<bool>(words >> record.seconds);
        else throw Error(record_error(path, number, "unknown field '" + field + "'"));
        if (!ok) throw Error(record_error(path, number, "bad value of '" + field + "'"));
    }
    if (!header) throw Error(record_error(path, 1, "empty record"));
    if (record.key.empty() || record.source_hash.empty())
        throw Error(record_error(path, number, "record lacks its key or source_hash"));
    return record;
}

void write_prepared_record(const PreparedRecord& record, const std::string& path) {
    std::filesystem::create_directories(std::filesystem::path(path).parent_path());
    // Written aside and renamed, so that a reader in another process never sees half a record.
    const std::string partial = path + ".partial-" + std::to_string(::getpid());
    std::ofstream out(partial);
    out << kRecordHeader << "\nmodel " << record.model << "\nresolution " << record.resolution << "\nsource_hash "
        << record.source_hash << "\nkey " << record.key << "\ntets " << record.tets << "\nalpha "
        << std::setprecision(17) << record.alpha << "\nseconds " << std::setprecision(4) << record.seconds << "\n";
    if (!out.flush()) throw Error(partial + ": cannot write file");
    out.close();
    std::filesystem::rename(partial, path);
}

TetMesh prepared_mesh(const std::string& model, int resolution) {
    const ModelInfo& info = thesis_model(model);
    target_tets(model, resolution);  // checks the resolution
    const std::string record_path = prepared_record_path(model, resolution);
    const std::string what = "mesh " + model + " resolution " + std::to_string(resolution);
    std::error_code ignored;
    if (!std::filesystem::is_regular_file(record_path, ignored))
        throw Error(what + " is not prepared; run `kdet prepare` (cache: " + cache_dir() + ")");
    const PreparedRecord record = read_prepared_record(record_path);
    // The source may be absent here (a cache copied from elsewhere); when present it must still match.
    const std::string source = (std::filesystem::path(data_dir()) / info.source_file).string();
    if (std::filesystem::is_regular_file(source, ignored) && file_hash(source) != record.source_hash)
        throw Error(what + " is out of date: " + source + " changed since it was prepared; run `kdet prepare` (cache: " +
                    cache_dir() + ")");
    const std::string stem = prepared_mesh_stem(record.key);
    if (!std::filesystem::is_regular_file(stem + ".ele", ignored))
        throw Error(what + " is not prepared: " + stem + ".ele is missing; run `kdet prepare` (cache: " + cache_dir() +
                    ")");
    return read_tetgen(stem);
}

std::string content_hash(const std::string& bytes) {
    std::uint64_t hash = 14695981039346656037ull;
    for (const char c : bytes) {
        hash ^= static_cast<unsigned char>(c);
        hash *= 1099511628211ull;
    }
    std::ostringstream hex;
    hex << std::hex << std::setw(16) << std::setfill('0') << hash;
    return hex.str();
}

std::string file_hash(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path + ": cannot open file");
    std::ostringstream bytes;
    bytes << in.rdbuf();
    if (in.bad()) throw Error(path + ": cannot read file");
    return content_hash(bytes.str());
}

} // namespace kdet
