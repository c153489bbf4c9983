#pragma once
/// @file scenes.hpp
/// @brief Part of the benchmark harness (the kdet_scenes target), not of the kdet library: meshes and
/// moving scenes that the code builds itself (so that kdet runs without data files), the thesis
/// scenes, scene files and recordings.

#include <kdet/detector.hpp>
#include <kdet/mesh.hpp>

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace kdet {

/// @brief A full box of nx*ny*nz cubes of edge `cell_size`, corner at the origin, each split into 6 tets.
///
/// Every cube is split along its main diagonal (Kuhn/Freudenthal split), which is conforming between
/// neighbouring cubes; all tets are positively oriented, i.e. dot(b-a, cross(c-a, d-a)) > 0.
/// Vertex (i, j, k) of the grid sits at (i, j, k) * cell_size.
/// Throws kdet::Error for a non-positive count or cell size, or more vertices than 32-bit indices hold.
TetMesh make_box_mesh(int nx, int ny, int nz, double cell_size);

/// @brief A solid torus around the z axis, centred at the origin, as a conforming tet mesh.
///
/// The region (sqrt(x^2+y^2) - major_radius)^2 + z^2 < minor_radius^2 is sampled on a regular grid:
/// cubes whose centre is inside are kept and split as in make_box_mesh; unused vertices are removed.
/// The grid is shifted slightly off the torus's symmetry planes and its cell size is chosen so that the
/// tet count is within 10% of `target_tets` (within 1% for large targets); below a few hundred tets the
/// mesh is too coarse to look like a torus, but it is still valid.
/// Throws kdet::Error unless 0 < minor_radius < major_radius and target_tets > 0.
TetMesh make_torus_mesh(double major_radius, double minor_radius, std::size_t target_tets);

/// @brief An animated benchmark scene: objects with fixed tet meshes whose vertices move every frame.
/// The bench tool and the tests drive every scene through this interface.
class Scene {
public:
    virtual ~Scene() = default;
    /// @brief Short name, as given on the command line.
    virtual std::string name() const = 0;
    virtual std::size_t num_objects() const = 0;
    virtual int num_frames() const = 0;
    /// @brief The tets (and rest positions) of `object`; the tets change between frames only in a
    /// scene whose changes_tets() says so.
    virtual const TetMesh& rest_mesh(std::size_t object) const = 0;
    /// @brief Vertex positions of `object` at `frame` (0-based) as x y z; `out` is resized.
    virtual void positions(std::size_t object, int frame, std::vector<float>& out) const = 0;
    virtual void positions(std::size_t object, int frame, std::vector<double>& out) const = 0;
    /// @brief Whether the scene asks for collisions between objects @p a and @p b (default: every pair).
    virtual bool checks_pair(std::size_t a, std::size_t b) const { return a != b; }
    /// @brief The collision filter of @p object (Detector::set_collision_filter), which leaves out more
    /// pairs between objects than checks_pair does (default: group 1, every mask bit: none).
    virtual CollisionFilter collision_filter(std::size_t /*object*/) const { return {}; }
    /// @brief Whether the scene asks for self-collisions of @p object (default: none).
    virtual bool checks_self(std::size_t /*object*/) const { return false; }
    /// @brief Whether the tets of some object change between frames (cutting, tearing): then a
    /// frame's tets are tets()', set with Detector::set_tets (default: they never change).
    virtual bool changes_tets() const { return false; }
    /// @brief The tets of `object` at `frame` (4 indices each, into rest_mesh(object)'s vertices).
    virtual void tets(std::size_t object, int /*frame*/, std::vector<std::uint32_t>& out) const { out = rest_mesh(object).tets; }
    /// @brief Whether @p object never moves (its positions are the same in every frame): it is added as
    /// a static object (Detector::set_static) and its positions are given once (default: none).
    virtual bool is_static(std::size_t /*object*/) const { return false; }
    /// @brief The resolution (1-4) its meshes were built at, or 0 for a scene that has none (procedural,
    /// tearing, recordings, folders of frames, scene files of mesh files only). A scene may fix it
    /// whatever was requested: pass_through_armadillos is at 2. A scene file whose prepared models
    /// follow the request for some objects and fix it for others gives the requested one.
    virtual int resolution() const { return 0; }
};

/// @brief Sets the tets of `scene`'s objects at `frame` in `detector` (ids in scene order from
/// `first_id`) where they differ from `current` (each object's tets as last set, updated), for a scene
/// whose tets change (Scene::changes_tets); does nothing for any other.
void set_scene_tets(Detector& detector, const Scene& scene, int frame, std::vector<std::vector<std::uint32_t>>& current,
                    ObjectId first_id = 0);

/// @brief The objects of a scene whose self-collision add_scene_objects() switches on.
enum class SceneSelfCollision {
    none,   ///< none (`kdet bench -s no`)
    every,  ///< every object (`-s yes`, the thesis's self-collision runs)
    marked, ///< those the scene marks (Scene::checks_self: a scene file's `self OBJECT`; `-s scene`)
};

/// @brief "no", "yes" or "scene": the value of `kdet bench -s` and its CSV files.
const char* to_string(SceneSelfCollision self);

/// @brief Whether @p self switches on the self-collision of @p scene's @p object.
bool self_collision_of(const Scene& scene, std::size_t object, SceneSelfCollision self);

/// @brief Adds every object of @p scene to @p detector (ids in scene order, from the detector's next
/// id on), with self-collision of the objects @p self names, collisions between the object pairs the
/// scene checks only, its collision filters, and its static objects static.
void add_scene_objects(Detector& detector, const Scene& scene, SceneSelfCollision self);

/// @brief add_scene_objects() with self-collision of every object (@p every) or of none.
inline void add_scene_objects(Detector& detector, const Scene& scene, bool every) {
    add_scene_objects(detector, scene, every ? SceneSelfCollision::every : SceneSelfCollision::none);
}

/// @brief Size of a ProceduralScene.
struct ProceduralSceneOptions {
    /// Tets of both objects together (half each, within about 10%); 100 to 20'000'000.
    std::size_t total_tets = 100000;
    /// Number of frames of the motion; at least 1.
    int frames = 120;
};

/// @brief Two deforming tori that approach, pass through each other and separate again.
///
/// Both objects share one rest mesh: a torus around the local z axis with major radius 1 and minor
/// radius 0.4. Object 0 lies flat (ring in the xy plane), object 1 stands upright (ring in the xz plane),
/// so their tubes cross like chain links. They start on the x axis with disjoint bounding boxes, move
/// towards each other until their centres coincide at the middle of the sequence, where the tubes cross
/// each other at two places, and move apart again along the same path, ending as they started.
/// The frame of deepest interpenetration is (num_frames() - 1) / 2 (both middle frames for an even count).
///
/// On top of that rigid motion every vertex moves every frame: each torus spins about its own axis,
/// twists (a rotation about its axis that grows with the height above the ring plane) and wobbles
/// (its centre line waves along the axis by 5% of the minor radius). Both deformations preserve volume
/// and are mild enough that no tet inverts.
class ProceduralScene final : public Scene {
public:
    /// @brief Builds the rest mesh. Throws kdet::Error for total_tets outside [100, 20'000'000] or frames < 1.
    explicit ProceduralScene(const ProceduralSceneOptions& options = {});

    /// @brief "procedural".
    std::string name() const override;
    /// @brief Number of objects: 2.
    std::size_t num_objects() const override;
    /// @brief Number of frames of the motion.
    int num_frames() const override;
    /// @brief The undeformed torus of `object` in its local frame (the same mesh for both objects).
    /// Throws kdet::Error for an object index out of range.
    const TetMesh& rest_mesh(std::size_t object) const override;

    /// @brief Vertex positions of `object` at `frame` (0-based) as x y z floats; `out` is resized.
    /// Parallel with OpenMP; deterministic (bit-identical for any thread count).
    /// Throws kdet::Error for an object or frame out of range.
    void positions(std::size_t object, int frame, std::vector<float>& out) const override;
    /// @brief The same motion in double (for writing files); the float overload rounds these values.
    void positions(std::size_t object, int frame, std::vector<double>& out) const override;

private:
    template <typename Real>
    void write_positions(std::size_t object, int frame, std::vector<Real>& out) const;

    ProceduralSceneOptions options_;
    TetMesh torus_;
    double start_separation_ = 0.0; ///< distance of the two centres at frame 0
};

/// @brief `heap`: small boxes (2 x 2 x 2 cubes, 48 tets each; 125, 343, 729 or 1000 of them at
/// resolution 1-4) released layer by layer over a static floor (object 0), falling and coming to rest
/// in columns that overlap a little sideways and downwards: many objects and contacts between them
/// and with the floor. Collision filters keep the bodies of one layer from colliding with each other
/// (group 2 for even layers, 4 for odd ones, each masking the floor's group 1 and the other layers'
/// group), so their sideways overlaps are left out while layers press on each other and the floor. Deterministic, built in code. Throws kdet::Error for a resolution outside 1-4.
std::unique_ptr<Scene> make_heap_scene(int resolution);

/// @brief `drape`: a square sheet one cube (three tets) thick falls onto a static ball (object 0),
/// lies a third of its thickness into it, wraps over it down to the equator (a large contact area) and
/// then pleats around it where it hangs until the pleats fold over themselves (self-contact). Sheets of
/// 40 to 160 cubes a side at resolution 1-4 (9,600 to 153,600 tets). Throws kdet::Error for a
/// resolution outside 1-4.
std::unique_ptr<Scene> make_drape_scene(int resolution);

/// @brief `graded`: a static unit block whose cubes halve in size toward a point inside it, from a
/// quarter of the block down 10 to 13 times at resolution 1-4 (tet sizes over 3 to 3.9 decades; not
/// conforming where cube sizes change),
/// and an upright torus of 10k-40k tets of one size rolling along x through that point. Throws
/// kdet::Error for a resolution outside 1-4.
std::unique_ptr<Scene> make_graded_scene(int resolution);

/// @brief What open_scene needs besides the name.
struct SceneRequest {
    int resolution = 1;                     ///< 1-4, for the thesis scenes
    ProceduralSceneOptions procedural;      ///< size of the "procedural" scene
};

/// @brief Opens a scene by name or path.
///
/// Names: "procedural" (built in, needs no data) and the thesis scenes "armadillos",
/// "buddha_and_armadillo", "bunny_and_planck" (at `request.resolution`, 1-4) and
/// "pass_through_armadillos" (always resolution 2); these read the meshes `kdet prepare` made (see
/// prepared_mesh). A path opens a scene file (read_scene_file; a name ending in ".scene"), a recording
/// (read_recording; ".kdetrec") or a folder of per-frame meshes (read_frame_folder).
/// Throws kdet::Error for a resolution outside 1-4 (whatever the scene), naming the known scenes for
/// an unknown name, and saying what is missing and where it was looked for when data is missing.
std::unique_ptr<Scene> open_scene(const std::string& name, const SceneRequest& request = {});

/// @brief Names open_scene accepts, for help texts and error messages.
std::vector<std::string> scene_names();

/// @brief Whether open_scene takes @p argument as a scene (one of scene_names(), a path ending in
/// ".scene" or ".kdetrec", or a folder) rather than refusing it as an unknown name; such a scene may
/// still fail to open (a missing or malformed file, a model not prepared).
bool names_a_scene(const std::string& argument);

/// @brief Reads a scene file (the format of docs/scenes.md): objects with their meshes, placement and
/// scripted motion (rigid keyframes and smooth deformations), the number of frames and the collisions
/// checked. Objects without a fixed resolution take `request.resolution`. Throws kdet::Error
/// "path:line: what" for a bad file and a clear message for a missing mesh.
std::unique_ptr<Scene> read_scene_file(const std::string& path, const SceneRequest& request = {});

/// @brief Plays back a simulation recorded elsewhere: a folder of per-frame tet meshes, one file per
/// frame in the order of the numbers in their names (frame_9 before frame_10). The files are legacy
/// VTK (.vtk) or TetGen (.node, with the tets of the folder's single .ele file); all frames must have
/// the same vertex count and tets. One folder is one object; a folder of such folders (sorted by
/// name) is one object each, with the same number of frames.
std::unique_ptr<Scene> read_frame_folder(const std::string& path);

/// @brief Plays back a recording in kdet's binary format (.kdetrec, see docs/scenes.md): the tets of
/// each object once, then float32 positions per frame, read frame by frame from the file. Reads
/// KDETREC2 and the older KDETREC1 (no static objects or collision filters).
std::unique_ptr<Scene> read_recording(const std::string& path);

/// @brief Records every frame of @p scene into @p path in the .kdetrec format (KDETREC2), with its
/// collision settings: self-collision, checked pairs, collision filters and static objects (whose
/// positions are stored once). Positions are stored as float32, as the detector uses them. Throws for a
/// scene whose tets change (Scene::changes_tets), which a recording cannot hold.
void write_recording(const Scene& scene, const std::string& path);

/// @brief Bends a straight bar so that, for angles above 2*pi, its two ends pass through each other.
///
/// `bar` is a straight bar along x (for example make_box_mesh(20, 2, 2, h)). The bar is wrapped around
/// an axis parallel to y, above the bar, keeping its centre line's length: the centre line becomes a
/// circular arc of `angle` radians (negative bends the other way). At |angle| = 2*pi the end faces meet;
/// beyond it the end regions overlap, which gives a mesh with many self-collision pairs.
/// `out_positions` (x y z per vertex) is resized; the tets of `bar` apply unchanged.
/// Throws kdet::Error for an empty or zero-length bar, or when the bar is thicker (along z) than the
/// bend radius allows (tets would turn inside out).
void fold_bar(const TetMesh& bar, double angle, std::vector<double>& out_positions);

} // namespace kdet
