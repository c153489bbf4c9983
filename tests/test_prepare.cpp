// The thesis models, the cache of prepared meshes and `kdet prepare` (thesis Table 5.2).

#include "prepare_support.hpp"
#include "test_support.hpp"

#include <kdet/error.hpp>
#include <kdet/prepare.hpp>

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace kdet::test {

std::string run_prepare(const std::string& arguments, bool& unavailable) {
    unavailable = true;
#ifdef KDET_CLI_PATH
    use_default_data_dir();
    const std::string command = std::string(KDET_CLI_PATH) + " prepare " + arguments + " 2>&1";
    FILE* pipe = popen(command.c_str(), "r");
    if (pipe == nullptr) return "cannot run " + command;
    std::string output;
    char buffer[4096];
    while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) output += buffer;
    if (pclose(pipe) == 0) return "";
    unavailable = output.find("built without CGAL") != std::string::npos ||
                  output.find("tetgen not found") != std::string::npos ||
                  output.find("not found in") != std::string::npos;
    return "kdet prepare " + arguments + ": " + output;
#else
    (void)arguments;
    return "the kdet command is not built (KDET_BUILD_TOOLS=OFF)";
#endif
}

namespace {

/// @brief Sets an environment variable for one test and restores it afterwards.
class ScopedEnv {
public:
    ScopedEnv(const char* name, const std::string& value) : name_(name) {
        if (const char* old = std::getenv(name)) old_ = old, had_ = true;
        setenv(name, value.c_str(), 1);
    }
    ~ScopedEnv() { had_ ? setenv(name_, old_.c_str(), 1) : unsetenv(name_); }

private:
    const char* name_;
    std::string old_;
    bool had_ = false;
};

std::filesystem::path fresh_dir(const std::string& name) {
    const auto dir = std::filesystem::temp_directory_path() / ("kdet-test-" + name + "-" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

TEST(ThesisModels, TableFivePointTwo) {
    EXPECT_EQ(thesis_models().size(), 4u);
    EXPECT_EQ(target_tets("armadillo", 1), 10121u);
    EXPECT_EQ(target_tets("happy-buddha", 2), 28584u);
    EXPECT_EQ(target_tets("max-planck", 3), 43648u);
    EXPECT_EQ(target_tets("bunny", 4), 99201u);
    EXPECT_THROW(target_tets("bunny", 5), Error);
    try {
        thesis_model("teapot");
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("known models: armadillo, happy-buddha, max-planck, bunny"),
                  std::string::npos);
    }
}

TEST(PreparedCache, HashIsFnv1a) {
    EXPECT_EQ(content_hash(""), "cbf29ce484222325");
    EXPECT_EQ(content_hash("a"), "af63dc4c8601ec8c");
}

TEST(PreparedCache, CacheDirFollowsTheEnvironment) {
    ScopedEnv cache("KDET_CACHE_DIR", "/somewhere/kdet");
    EXPECT_EQ(cache_dir(), "/somewhere/kdet");
    ScopedEnv empty("KDET_CACHE_DIR", "");
    ScopedEnv xdg("XDG_CACHE_HOME", "/xdg");
    EXPECT_EQ(cache_dir(), "/xdg/kdet");
}

TEST(PreparedCache, MissingMeshSaysWhatToRun) {
    const auto dir = fresh_dir("empty-cache");
    ScopedEnv cache("KDET_CACHE_DIR", dir.string());
    try {
        prepared_mesh("armadillo", 2);
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()),
                  "mesh armadillo resolution 2 is not prepared; run `kdet prepare` (cache: " + dir.string() + ")");
    }
    std::filesystem::remove_all(dir);
}

TEST(PreparedCache, RecordRoundTripAndDamagedRecord) {
    const auto dir = fresh_dir("record");
    ScopedEnv cache("KDET_CACHE_DIR", dir.string());
    PreparedRecord record;
    record.model = "bunny";
    record.resolution = 3;
    record.source_hash = "0123456789abcdef";
    record.key = "fedcba9876543210";
    record.tets = 56000;
    record.alpha = 1.0 / 57.5;
    record.seconds = 8.5;
    const std::string path = prepared_record_path("bunny", 3);
    write_prepared_record(record, path);
    const PreparedRecord back = read_prepared_record(path);
    EXPECT_EQ(back.model, "bunny");
    EXPECT_EQ(back.resolution, 3);
    EXPECT_EQ(back.key, record.key);
    EXPECT_EQ(back.tets, record.tets);
    EXPECT_DOUBLE_EQ(back.alpha, record.alpha);

    std::ofstream(path, std::ios::app) << "colour blue\n";
    try {
        read_prepared_record(path);
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), path + ":9: unknown field 'colour'");
    }
    std::filesystem::remove_all(dir);
}

// All 16 meshes take about a minute on two cores the first time and nothing once cached.
TEST(Prepare, TetCountsWithinTenPercentOfTable) {
    KDET_PREPARE_OR_SKIP("");
    for (const ModelInfo& model : thesis_models()) {
        for (int resolution = 1; resolution <= 4; ++resolution) {
            const TetMesh mesh = prepared_mesh(model.name, resolution);
            const double target = static_cast<double>(target_tets(model.name, resolution));
            EXPECT_NEAR(static_cast<double>(mesh.num_tets()) / target, 1.0, 0.10)
                << model.name << " resolution " << resolution << ": " << mesh.num_tets() << " tets";
            // Normalised as the scene files expect: centred, largest extent about 1 (the wrap adds a little).
            double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
            for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
                lo[i % 3] = std::min(lo[i % 3], mesh.positions[i]);
                hi[i % 3] = std::max(hi[i % 3], mesh.positions[i]);
            }
            const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
            EXPECT_NEAR(extent, 1.0, 0.03) << model.name << " resolution " << resolution;
            for (int a = 0; a < 3; ++a) EXPECT_NEAR(lo[a] + hi[a], 0.0, 0.02) << model.name;
        }
    }
}

TEST(Prepare, DeterministicAndCached) {
    const auto dir = fresh_dir("prepare-twice");
    ScopedEnv cache("KDET_CACHE_DIR", dir.string());
    KDET_PREPARE_OR_SKIP("max-planck -r 1");
    const PreparedRecord first = read_prepared_record(prepared_record_path("max-planck", 1));
    const TetMesh a = prepared_mesh("max-planck", 1);
    // Cached: nothing is rebuilt, the record stays.
    KDET_PREPARE_OR_SKIP("max-planck -r 1");
    EXPECT_EQ(read_prepared_record(prepared_record_path("max-planck", 1)).seconds, first.seconds);
    // Rebuilt from scratch: the same mesh, bit for bit.
    KDET_PREPARE_OR_SKIP("max-planck -r 1 --force");
    const TetMesh b = prepared_mesh("max-planck", 1);
    EXPECT_EQ(a.tets, b.tets);
    EXPECT_EQ(a.positions, b.positions);
    std::filesystem::remove_all(dir);
}

TEST(Prepare, AnySurfaceToARequestedSize) {
    const auto dir = fresh_dir("surface");
    use_default_data_dir();
    const std::string surface = data_dir() + "/bunny.off";
    const std::string out = (dir / "bunny").string();
    KDET_PREPARE_OR_SKIP("--surface " + surface + " --tets 5000 --out " + out);
    const TetMesh mesh = read_tetgen(out);
    EXPECT_NEAR(static_cast<double>(mesh.num_tets()) / 5000.0, 1.0, 0.10);
    std::filesystem::remove_all(dir);
}

} // namespace
} // namespace kdet::test
