#pragma once
/// @file prepare.hpp
/// @brief Part of the benchmark harness (the kdet_scenes target), not of the kdet library: where the
/// source models are found, the thesis models as tetrahedral meshes with their sizes (thesis Table
/// 5.2), and the cache that `kdet prepare` fills. This target only reads the cache; making the meshes
/// needs CGAL and TetGen and is the job of the `kdet prepare` command.

#include <kdet/mesh.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace kdet {

/// @brief One source model of the thesis scenes.
struct ModelInfo {
    std::string name;                        ///< "armadillo", "happy-buddha", "max-planck" or "bunny"
    std::string source_file;                 ///< triangle surface inside data_dir()
    std::array<std::size_t, 4> target_tets;  ///< tet count of resolutions 1-4 (thesis Table 5.2)
};

/// @brief The four models of the thesis, in the order of Table 5.2.
const std::vector<ModelInfo>& thesis_models();

/// @brief The model called @p name. Throws kdet::Error naming the known models for another name.
const ModelInfo& thesis_model(const std::string& name);

/// @brief The tet count Table 5.2 gives for @p model at @p resolution (1-4); prepared meshes land
/// within 10 % of it. Throws kdet::Error for an unknown model or a resolution outside 1-4.
std::size_t target_tets(const std::string& model, int resolution);

/// @brief The folder holding the source models: $KDET_DATA_DIR when set and non-empty, else
/// "../shared/models" (relative to the working directory).
std::string data_dir();

/// @brief The path of model @p file inside data_dir().
/// @throws Error "model 'x' not found in DIR (...)" when there is no such file.
std::string data_path(const std::string& file);

/// @brief Where prepared meshes are kept: $KDET_CACHE_DIR when set and non-empty, else
/// $XDG_CACHE_HOME/kdet, else $HOME/.cache/kdet.
std::string cache_dir();

/// @brief What `kdet prepare` records for one prepared mesh, in `cache_dir()/<model>-r<resolution>.txt`.
struct PreparedRecord {
    std::string model;
    int resolution = 0;
    std::string source_hash;  ///< content_hash() of the source surface it was made from
    std::string key;          ///< cache key: hash of source, parameters and tool versions
    std::size_t tets = 0;
    double alpha = 0.0;       ///< alpha of the wrap, in units of the source's bounding-box diagonal
    double seconds = 0.0;     ///< time the search for alpha took
};

/// @brief The path of the record of @p model at @p resolution.
std::string prepared_record_path(const std::string& model, int resolution);

/// @brief The TetGen stem (`stem.node`, `stem.ele`) of the mesh with cache key @p key.
std::string prepared_mesh_stem(const std::string& key);

/// @brief Reads a record; throws kdet::Error with "path:line: ..." for a damaged one.
PreparedRecord read_prepared_record(const std::string& path);

/// @brief Writes a record (creating the cache folders as needed).
void write_prepared_record(const PreparedRecord& record, const std::string& path);

/// @brief The prepared tet mesh of @p model at @p resolution, read from the cache.
///
/// The mesh is centred at the origin with its largest bounding-box extent 1, y up, as the scene files
/// expect. Throws kdet::Error "mesh armadillo resolution 2 is not prepared; run `kdet prepare` (cache:
/// DIR)" when it is missing, and a similar message when its source surface in data_dir() changed
/// since it was prepared.
TetMesh prepared_mesh(const std::string& model, int resolution);

/// @brief A 64-bit FNV-1a hash of @p bytes as 16 hex digits; the cache keys are built from it.
std::string content_hash(const std::string& bytes);

/// @brief content_hash() of the whole content of the file at @p path; throws kdet::Error when it
/// cannot be read.
std::string file_hash(const std::string& path);

} // namespace kdet
