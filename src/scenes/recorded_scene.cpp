/// @file recorded_scene.cpp
/// @brief Scenes played back from per-frame mesh files or from kdet's binary recordings (.kdetrec).

#include "io/text_reader.hpp"

#include <kdet/error.hpp>
#include <kdet/io.hpp>
#include <kdet/scenes.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fcntl.h>
#include <sys/stat.h>
#include <filesystem>
#include <fstream>
#include <unistd.h>

namespace kdet {
namespace {

namespace fs = std::filesystem;

/// Recordings start with "KDETREC" and their version: 1 without static objects and filters, 2 with.
constexpr char kMagic[7] = {'K', 'D', 'E', 'T', 'R', 'E', 'C'};
constexpr unsigned char flag_self = 1, flag_static = 2;

void check_frame(const std::string& scene, int frame, int frames) {
    if (frame < 0 || frame >= frames)
        throw Error("scene " + scene + " has no frame " + std::to_string(frame) + " (it has " + std::to_string(frames) +
                    ")");
}

template <typename Real>
void copy_positions(const std::vector<double>& in, std::vector<Real>& out) {
    out.resize(in.size());
    std::transform(in.begin(), in.end(), out.begin(), [](double x) { return static_cast<Real>(x); });
}

/// @brief Orders file names by the numbers in them, so that frame_9 comes before frame_10.
bool natural_less(const std::string& a, const std::string& b) {
    std::size_t i = 0, j = 0;
    while (i < a.size() && j < b.size()) {
        if (std::isdigit(static_cast<unsigned char>(a[i])) && std::isdigit(static_cast<unsigned char>(b[j]))) {
            std::size_t ei = i, ej = j;
            while (ei < a.size() && std::isdigit(static_cast<unsigned char>(a[ei]))) ++ei;
            while (ej < b.size() && std::isdigit(static_cast<unsigned char>(b[ej]))) ++ej;
            const std::string na = a.substr(i, ei - i), nb = b.substr(j, ej - j);
            const std::size_t za = na.find_first_not_of('0'), zb = nb.find_first_not_of('0');
            const std::string ta = za == std::string::npos ? "" : na.substr(za);
            const std::string tb = zb == std::string::npos ? "" : nb.substr(zb);
            if (ta.size() != tb.size()) return ta.size() < tb.size();
            if (ta != tb) return ta < tb;
            i = ei;
            j = ej;
        } else {
            if (a[i] != b[j]) return a[i] < b[j];
            ++i;
            ++j;
        }
    }
    return a.size() - i < b.size() - j;
}

/// @brief The last number in a file's stem ("frame_012.vtk": 12), or -1 without one.
long long frame_number(const std::string& file) {
    const std::string stem = fs::path(file).stem().string();
    const std::size_t end = stem.find_last_of("0123456789");
    if (end == std::string::npos) return -1;
    std::size_t begin = end;
    while (begin > 0 && std::isdigit(static_cast<unsigned char>(stem[begin - 1]))) --begin;
    return end - begin < 18 ? std::stoll(stem.substr(begin, end - begin + 1)) : -1;
}

/// @brief The frame files of one object folder: .vtk, or .node (each with its .ele), in any case, in
/// the order of their numbers, which must run without gaps or repeats where the names carry them.
std::vector<std::string> frame_files(const fs::path& folder) {
    std::vector<std::string> vtk, node;
    for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
        if (!entry.is_regular_file()) continue;
        const std::string ext = io::lowercase_extension(entry.path().string());
        if (ext == ".vtk") vtk.push_back(entry.path().string());
        if (ext == ".node") node.push_back(entry.path().string());
        if (ext == ".msh" || ext == ".mesh")
            throw Error(entry.path().string() + ": a frame folder holds .vtk or .node frames, not " + ext);
    }
    if (!vtk.empty() && !node.empty())
        throw Error(folder.string() + ": holds both .vtk and .node frames; keep one kind per folder");
    std::vector<std::string>& files = vtk.empty() ? node : vtk;
    // By number, then by name where numbers tie (frame_03 and frame_3), so that the order never
    // depends on the directory's.
    std::sort(files.begin(), files.end(), [](const std::string& a, const std::string& b) {
        return natural_less(a, b) || (!natural_less(b, a) && a < b);
    });
    for (std::size_t f = 1; f < files.size(); ++f) {
        const long long before = frame_number(files[f - 1]), number = frame_number(files[f]);
        if (before < 0 || number < 0) continue;
        if (number == before)
            throw Error(folder.string() + ": " + fs::path(files[f - 1]).filename().string() + " and " +
                        fs::path(files[f]).filename().string() + " are both frame " + std::to_string(number));
        if (number != before + 1)
            throw Error(folder.string() + ": the frames jump from " + fs::path(files[f - 1]).filename().string() + " to " +
                        fs::path(files[f]).filename().string() + " (a frame missing?)");
    }
    return files;
}

/// @brief A folder's own name, also when given with a trailing '/'.
std::string folder_name(const std::string& path) {
    fs::path folder(path);
    if (folder.filename().empty()) folder = folder.parent_path();
    return folder.filename().string();
}

/// @brief One object per folder; each frame is read from its file when asked for.
class FrameFolderScene final : public Scene {
public:
    explicit FrameFolderScene(const std::string& path) : name_(folder_name(path)) {
        if (!fs::is_directory(path)) throw Error(path + ": not a folder of frames");
        std::vector<fs::path> folders;
        if (!frame_files(path).empty()) {
            folders.emplace_back(path);
        } else {
            for (const fs::directory_entry& entry : fs::directory_iterator(path))
                if (entry.is_directory()) folders.push_back(entry.path());
            std::sort(folders.begin(), folders.end());
        }
        for (const fs::path& folder : folders) {
            files_.push_back(frame_files(folder));
            if (files_.back().empty())
                throw Error(folder.string() + ": no frame files (.vtk, or .node with .ele) found");
            if (files_.back().size() != files_.front().size())
                throw Error(folder.string() + ": " + std::to_string(files_.back().size()) + " frames, but " +
                            folders.front().string() + " has " + std::to_string(files_.front().size()));
            meshes_.push_back(read_tet_mesh(files_.back().front()));
        }
        if (files_.empty()) throw Error(path + ": no frame files (.vtk, or .node with .ele) and no object folders found");
    }

    std::string name() const override { return name_; }
    std::size_t num_objects() const override { return meshes_.size(); }
    int num_frames() const override { return static_cast<int>(files_.front().size()); }
    const TetMesh& rest_mesh(std::size_t object) const override {
        if (object >= meshes_.size()) throw Error("scene " + name_ + " has no object " + std::to_string(object));
        return meshes_[object];
    }
    void positions(std::size_t object, int frame, std::vector<float>& out) const override {
        copy_positions(read_frame(object, frame), out);
    }
    void positions(std::size_t object, int frame, std::vector<double>& out) const override {
        out = read_frame(object, frame);
    }

private:
    std::vector<double> read_frame(std::size_t object, int frame) const {
        const TetMesh& rest = rest_mesh(object);
        check_frame(name_, frame, num_frames());
        const std::string& file = files_[object][static_cast<std::size_t>(frame)];
        TetMesh mesh = read_tet_mesh(file);
        if (mesh.num_vertices() != rest.num_vertices())
            throw Error(file + ": " + std::to_string(mesh.num_vertices()) + " vertices, but the first frame " +
                        files_[object].front() + " has " + std::to_string(rest.num_vertices()));
        if (mesh.tets != rest.tets)
            throw Error(file + ": its tets differ from those of the first frame " + files_[object].front());
        return std::move(mesh.positions);
    }

    std::string name_;
    std::vector<std::vector<std::string>> files_;
    std::vector<TetMesh> meshes_;
};

// ---------------------------------------------------------------------------------------------
// .kdetrec: little-endian throughout.

void put_u32(std::ofstream& out, std::uint32_t value) {
    const unsigned char bytes[4] = {static_cast<unsigned char>(value), static_cast<unsigned char>(value >> 8),
                                    static_cast<unsigned char>(value >> 16), static_cast<unsigned char>(value >> 24)};
    out.write(reinterpret_cast<const char*>(bytes), 4);
}

std::uint32_t get_u32(const unsigned char* bytes) {
    return static_cast<std::uint32_t>(bytes[0]) | static_cast<std::uint32_t>(bytes[1]) << 8 |
           static_cast<std::uint32_t>(bytes[2]) << 16 | static_cast<std::uint32_t>(bytes[3]) << 24;
}

std::uint32_t narrow(std::size_t value, const std::string& what) {
    if (value > UINT32_MAX) throw Error("cannot record " + what + " " + std::to_string(value) + ": above 2^32 - 1");
    return static_cast<std::uint32_t>(value);
}

/// @brief A .kdetrec file: the header is read at once, the positions of a frame when asked for.
class RecordingScene final : public Scene {
public:
    explicit RecordingScene(const std::string& path) : path_(path), name_(fs::path(path).stem().string()) {
        fd_ = ::open(path.c_str(), O_RDONLY);
        if (fd_ < 0) throw Error(path + ": cannot open file");
        try {
            struct stat status {};
            if (::fstat(fd_, &status) != 0 || !S_ISREG(status.st_mode)) throw Error(path + ": not a regular file");
            file_size_ = static_cast<std::uint64_t>(status.st_size);
            read_header();
        } catch (...) {
            ::close(fd_);
            throw;
        }
    }
    ~RecordingScene() override { ::close(fd_); }
    RecordingScene(const RecordingScene&) = delete;
    RecordingScene& operator=(const RecordingScene&) = delete;

    std::string name() const override { return name_; }
    std::size_t num_objects() const override { return meshes_.size(); }
    int num_frames() const override { return frames_; }
    const TetMesh& rest_mesh(std::size_t object) const override {
        if (object >= meshes_.size()) throw Error("scene " + name_ + " has no object " + std::to_string(object));
        return meshes_[object];
    }
    void positions(std::size_t object, int frame, std::vector<float>& out) const override {
        read_frame(object, frame, out);
    }
    void positions(std::size_t object, int frame, std::vector<double>& out) const override {
        std::vector<float> values;
        read_frame(object, frame, values);
        out.assign(values.begin(), values.end());
    }
    bool checks_pair(std::size_t a, std::size_t b) const override {
        const auto pair = std::make_pair(std::min(a, b), std::max(a, b));
        return std::find(pairs_.begin(), pairs_.end(), pair) != pairs_.end();
    }
    bool checks_self(std::size_t object) const override { return object < self_.size() && self_[object]; }
    bool is_static(std::size_t object) const override { return object < static_.size() && static_[object]; }
    CollisionFilter collision_filter(std::size_t object) const override {
        return object < filters_.size() ? filters_[object] : CollisionFilter{};
    }

private:
    /// @brief Fails naming @p what when the file ends before @p offset + @p size, before anything is
    /// allocated for a count that the file cannot hold.
    void check_extent(std::uint64_t offset, std::uint64_t size, const std::string& what) const {
        if (offset > file_size_ || size > file_size_ - offset)
            throw Error(path_ + ": byte " + std::to_string(file_size_) + ": file ends inside " + what);
    }
    /// @brief Reads @p size bytes at @p offset; fails naming @p what when the file is shorter.
    std::vector<unsigned char> read_at(std::uint64_t offset, std::size_t size, const std::string& what) const {
        check_extent(offset, size, what);
        std::vector<unsigned char> bytes(size);
        std::size_t done = 0;
        while (done < size) {
            const ssize_t got = ::pread(fd_, bytes.data() + done, size - done, static_cast<off_t>(offset + done));
            if (got <= 0) throw Error(path_ + ": byte " + std::to_string(offset + done) + ": file ends inside " + what);
            done += static_cast<std::size_t>(got);
        }
        return bytes;
    }
    std::uint32_t read_u32(std::uint64_t& offset, const std::string& what) const {
        const std::uint32_t value = get_u32(read_at(offset, 4, what).data());
        offset += 4;
        return value;
    }

    void read_header() {
        std::uint64_t at = 0;
        const std::vector<unsigned char> magic = read_at(0, 8, "the header");
        if (std::memcmp(magic.data(), kMagic, 7) != 0 || (magic[7] != '1' && magic[7] != '2'))
            throw Error(path_ + ": byte 0: not a kdet recording (it starts with KDETREC1 or KDETREC2)");
        const int version = magic[7] - '0';
        at = 8;
        const std::uint32_t objects = read_u32(at, "the header");
        frames_ = static_cast<int>(std::min<std::uint32_t>(read_u32(at, "the header"), INT32_MAX));
        if (objects == 0 || frames_ == 0) throw Error(path_ + ": byte 8: a recording needs an object and a frame");
        frame_bytes_ = 0;
        for (std::uint32_t o = 0; o < objects; ++o) {
            const std::string what = "object " + std::to_string(o);
            TetMesh mesh;
            const std::uint32_t vertices = read_u32(at, what), tets = read_u32(at, what);
            const unsigned char flags = read_at(at, 1, what)[0];
            if (version >= 2 && (flags & ~(flag_self | flag_static)) != 0)
                throw Error(path_ + ": byte " + std::to_string(at) + ": " + what + ": unknown flags " + std::to_string(flags) +
                            " (1: self-collision, 2: static)");
            at += 1;
            self_.push_back(version >= 2 ? (flags & flag_self) != 0 : flags != 0);
            static_.push_back(version >= 2 && (flags & flag_static) != 0);
            CollisionFilter filter;
            if (version >= 2) {
                filter.group = read_u32(at, what);
                filter.mask = read_u32(at, what);
            }
            filters_.push_back(filter);
            const std::vector<unsigned char> bytes = read_at(at, 16ull * tets, "the tets of " + what);
            at += 16ull * tets;
            mesh.tets.resize(4ull * tets);
            for (std::size_t i = 0; i < mesh.tets.size(); ++i) mesh.tets[i] = get_u32(&bytes[4 * i]);
            vertex_counts_.push_back(vertices);
            object_offset_.push_back(static_.back() ? 0 : frame_bytes_);
            if (!static_.back()) frame_bytes_ += 12ull * vertices;
            meshes_.push_back(std::move(mesh));
        }
        const std::uint32_t pairs = read_u32(at, "the pairs");
        for (std::uint32_t p = 0; p < pairs; ++p) {
            const std::uint32_t a = read_u32(at, "the pairs"), b = read_u32(at, "the pairs");
            if (a >= objects || b >= objects || a == b)
                throw Error(path_ + ": byte " + std::to_string(at - 8) + ": bad object pair " + std::to_string(a) +
                            " " + std::to_string(b));
            pairs_.emplace_back(std::min<std::size_t>(a, b), std::max<std::size_t>(a, b));
        }
        // A static object's positions, once, in object order, before the frames.
        for (std::size_t o = 0; o < meshes_.size(); ++o)
            if (static_[o]) {
                object_offset_[o] = at;
                check_extent(at, 12ull * vertex_counts_[o], "the positions of static object " + std::to_string(o));
                at += 12ull * vertex_counts_[o];
            }
        data_offset_ = at;
        // The last frame must be there too: a cut-off file fails now, not half-way through a run.
        const std::uint64_t data_bytes = file_size_ - std::min(file_size_, data_offset_);
        if (frame_bytes_ > 0 && static_cast<std::uint64_t>(frames_) > data_bytes / frame_bytes_)
            check_extent(data_offset_, data_bytes + 1, "the last frame");
        // Bytes past the last frame: a header whose frame count was edited down, or two files joined.
        const std::uint64_t frames_end = data_offset_ + frame_bytes_ * static_cast<std::uint64_t>(frames_);
        if (file_size_ > frames_end)
            throw Error(path_ + ": byte " + std::to_string(frames_end) + ": " + std::to_string(file_size_ - frames_end) +
                        " bytes past the last of the " + std::to_string(frames_) + " frames the header announces");
        for (std::size_t o = 0; o < meshes_.size(); ++o) {
            std::vector<double> rest;
            positions(o, 0, rest);
            meshes_[o].positions = rest;
            validate_tet_mesh(meshes_[o], path_ + ": object " + std::to_string(o), {true});
        }
    }

    void read_frame(std::size_t object, int frame, std::vector<float>& out) const {
        if (object >= meshes_.size()) throw Error("scene " + name_ + " has no object " + std::to_string(object));
        check_frame(name_, frame, frames_);
        const std::size_t count = 3 * static_cast<std::size_t>(vertex_counts_[object]);
        const std::uint64_t offset =
            static_[object] ? object_offset_[object]
                            : data_offset_ + frame_bytes_ * static_cast<std::uint64_t>(frame) + object_offset_[object];
        const std::vector<unsigned char> bytes = read_at(offset, 4 * count, "frame " + std::to_string(frame));
        out.resize(count);
        for (std::size_t i = 0; i < count; ++i) {
            const std::uint32_t bits = get_u32(&bytes[4 * i]);
            std::memcpy(&out[i], &bits, 4);
            if (!std::isfinite(out[i]))
                throw Error(path_ + ": frame " + std::to_string(frame) + ", object " + std::to_string(object) + ": vertex " +
                            std::to_string(i / 3) + " has a non-finite coordinate");
        }
    }

    std::string path_, name_;
    int fd_ = -1;
    int frames_ = 0;
    std::vector<TetMesh> meshes_;
    std::vector<bool> self_, static_;
    std::vector<CollisionFilter> filters_;
    std::vector<std::pair<std::size_t, std::size_t>> pairs_;
    std::vector<std::uint64_t> vertex_counts_;
    std::vector<std::uint64_t> object_offset_; ///< in a frame's bytes; a static object's in the file

    std::uint64_t frame_bytes_ = 0, data_offset_ = 0, file_size_ = 0;
};

} // namespace

std::unique_ptr<Scene> read_frame_folder(const std::string& path) { return std::make_unique<FrameFolderScene>(path); }

std::unique_ptr<Scene> read_recording(const std::string& path) { return std::make_unique<RecordingScene>(path); }

void write_recording(const Scene& scene, const std::string& path) {
    if (scene.changes_tets())
        throw Error(path + ": scene " + scene.name() + " changes its tets from frame to frame, which a recording does not hold");
    std::ofstream out(path, std::ios::binary);
    if (!out) throw Error(path + ": cannot create file");
    out.write(kMagic, 7);
    out.put('2');
    put_u32(out, narrow(scene.num_objects(), "object count"));
    put_u32(out, narrow(static_cast<std::size_t>(scene.num_frames()), "frame count"));
    for (std::size_t o = 0; o < scene.num_objects(); ++o) {
        const TetMesh& mesh = scene.rest_mesh(o);
        put_u32(out, narrow(mesh.num_vertices(), "vertex count"));
        put_u32(out, narrow(mesh.num_tets(), "tet count"));
        out.put(static_cast<char>((scene.checks_self(o) ? flag_self : 0) | (scene.is_static(o) ? flag_static : 0)));
        const CollisionFilter filter = scene.collision_filter(o);
        put_u32(out, filter.group);
        put_u32(out, filter.mask);
        for (const std::uint32_t index : mesh.tets) put_u32(out, index);
    }
    std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
    for (std::size_t a = 0; a < scene.num_objects(); ++a)
        for (std::size_t b = a + 1; b < scene.num_objects(); ++b)
            if (scene.checks_pair(a, b)) pairs.emplace_back(static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b));
    put_u32(out, narrow(pairs.size(), "pair count"));
    for (const auto& [a, b] : pairs) {
        put_u32(out, a);
        put_u32(out, b);
    }
    std::vector<float> positions;
    const auto put_positions = [&](std::size_t object, int frame) {
        scene.positions(object, frame, positions);
        for (const float x : positions) {
            std::uint32_t bits;
            std::memcpy(&bits, &x, 4);
            put_u32(out, bits);
        }
    };
    for (std::size_t o = 0; o < scene.num_objects(); ++o)
        if (scene.is_static(o)) put_positions(o, 0);
    for (int f = 0; f < scene.num_frames(); ++f)
        for (std::size_t o = 0; o < scene.num_objects(); ++o)
            if (!scene.is_static(o)) put_positions(o, f);
    if (!out.flush()) throw Error(path + ": cannot write file");
}

} // namespace kdet
