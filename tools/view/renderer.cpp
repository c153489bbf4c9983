#include "renderer.hpp"

#include "surface.hpp"

#include <kdet/error.hpp>

#include <epoxy/gl.h>

#include <algorithm>
#include <string>

namespace kdet::view {

namespace {

// Positions arrive in attribute 0; contact normals add a direction in attribute 1 that the vertex
// shader scales, so their length changes without an upload. Normals of the flat shading come from
// screen-space derivatives, so the per-frame work is the positions alone.
const char* mesh_vertex_shader = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 offset;
uniform mat4 view;
uniform mat4 projection;
uniform vec4 clip_plane;
uniform float offset_scale;
out vec3 view_position;
void main() {
    vec3 world = position + offset * offset_scale;
    vec4 eye = view * vec4(world, 1.0);
    view_position = eye.xyz;
    gl_ClipDistance[0] = dot(clip_plane, vec4(world, 1.0));
    gl_Position = projection * eye;
}
)";

const char* mesh_fragment_shader = R"(#version 330 core
in vec3 view_position;
uniform vec4 color;
uniform int lit;
uniform int shade_back_faces;
out vec4 out_color;
void main() {
    if (lit == 0) {
        out_color = color;
        return;
    }
    vec3 n = cross(dFdx(view_position), dFdy(view_position));
    n = dot(n, n) > 0.0 ? normalize(n) : vec3(0.0, 0.0, 1.0);
    vec3 light = normalize(vec3(-0.35, 0.55, 1.0));
    float diffuse = max(dot(n, light), 0.0);
    float specular = pow(max(dot(n, normalize(light + vec3(0.0, 0.0, 1.0))), 0.0), 48.0);
    vec3 rgb = color.rgb * (0.32 + 0.68 * diffuse) + vec3(0.18 * specular * float(shade_back_faces));
    // The inside of a clipped surface: darker, so that it reads as the far wall.
    if (shade_back_faces == 1 && !gl_FrontFacing) rgb = color.rgb * (0.18 + 0.3 * diffuse);
    out_color = vec4(rgb, color.a);
}
)";

const char* background_vertex_shader = R"(#version 330 core
out float height;
void main() {
    vec2 corner = vec2(float((gl_VertexID & 1) << 2) - 1.0, float((gl_VertexID & 2) << 1) - 1.0);
    height = corner.y * 0.5 + 0.5;
    gl_Position = vec4(corner, 0.0, 1.0);
}
)";

const char* background_fragment_shader = R"(#version 330 core
in float height;
out vec4 out_color;
void main() {
    out_color = vec4(mix(vec3(0.30, 0.32, 0.36), vec3(0.11, 0.12, 0.14), clamp(height, 0.0, 1.0)), 1.0);
}
)";

/// @brief Throws with the driver's log unless @p object (a shader or a program) reached @p status;
/// the getters are the shader's or the program's own.
template <class GetParameter, class GetLog, class Delete>
void expect_status(GLuint object, GLenum status, GetParameter get_parameter, GetLog get_log, Delete destroy,
                   const char* failure) {
    GLint ok = 0;
    get_parameter(object, status, &ok);
    if (ok) return;
    char log[2048] = {};
    get_log(object, static_cast<GLsizei>(sizeof log), nullptr, log);
    destroy(object);
    throw Error(std::string("view: OpenGL ") + failure + ": " + log);
}

unsigned compile(GLenum kind, const char* source) {
    const GLuint shader = glCreateShader(kind);
    glShaderSource(shader, 1, &source, nullptr);
    glCompileShader(shader);
    expect_status(shader, GL_COMPILE_STATUS, glGetShaderiv, glGetShaderInfoLog, glDeleteShader, "shader does not compile");
    return shader;
}

unsigned link(const char* vertex, const char* fragment) {
    const GLuint v = compile(GL_VERTEX_SHADER, vertex), f = compile(GL_FRAGMENT_SHADER, fragment);
    const GLuint program = glCreateProgram();
    glAttachShader(program, v);
    glAttachShader(program, f);
    glLinkProgram(program);
    glDeleteShader(v);
    glDeleteShader(f);
    expect_status(program, GL_LINK_STATUS, glGetProgramiv, glGetProgramInfoLog, glDeleteProgram, "program does not link");
    return program;
}

GLint uniform(unsigned program, const char* name) { return glGetUniformLocation(program, name); }

void set_color(unsigned program, Color c, float alpha) { glUniform4f(uniform(program, "color"), c.r, c.g, c.b, alpha); }

Color scaled(Color c, float s) { return {c.r * s, c.g * s, c.b * s}; }

} // namespace

Color object_color(std::size_t object) {
    // Blues, violets and muted neutrals only: red belongs to the colliding tets, yellow to the margin's,
    // green to the tets that hold query points.
    static constexpr Color palette[] = {{0.30f, 0.56f, 0.92f}, {0.66f, 0.54f, 0.94f}, {0.36f, 0.78f, 0.84f},
                                        {0.72f, 0.74f, 0.78f}, {0.44f, 0.50f, 0.68f}, {0.74f, 0.66f, 0.56f}};
    return palette[object % (sizeof palette / sizeof palette[0])];
}

Color highlight_color() { return {0.96f, 0.20f, 0.12f}; }

Color margin_color() { return {0.98f, 0.92f, 0.30f}; }

Color point_color(int status) {
    // None of them red or of the objects' cool colours.
    static constexpr Color colors[] = {{1.0f, 1.0f, 1.0f}, {1.0f, 0.62f, 0.05f}, {0.95f, 0.15f, 0.95f}};
    return colors[status];
}

Color located_color() { return {0.45f, 0.90f, 0.15f}; }

Color normal_color() { return {1.0f, 0.6f, 0.8f}; }

Color selected_color() { return {0.95f, 0.95f, 0.95f}; }

Color partner_color() { return {0.0f, 0.62f, 0.52f}; }

Renderer::Renderer() {
    mesh_program_ = link(mesh_vertex_shader, mesh_fragment_shader);
    background_program_ = link(background_vertex_shader, background_fragment_shader);
    glGenVertexArrays(1, &empty_array_);
    glGenVertexArrays(1, &contacts_.array);
    glGenVertexArrays(1, &selection_.array);
    glGenVertexArrays(1, &points_.array);
}

Renderer::~Renderer() {
    release_scene();
    for (Stream* stream : {&contacts_, &selection_, &points_}) {
        release_buffer(stream->buffer, stream->capacity * sizeof(float));
        glDeleteVertexArrays(1, &stream->array);
    }
    glDeleteVertexArrays(1, &empty_array_);
    glDeleteProgram(background_program_);
    glDeleteProgram(mesh_program_);
}

unsigned Renderer::make_buffer(unsigned target, std::size_t bytes, const void* data, unsigned usage) {
    GLuint buffer = 0;
    glGenBuffers(1, &buffer);
    glBindBuffer(target, buffer);
    glBufferData(target, static_cast<GLsizeiptr>(bytes), data, usage);
    ++stats_.allocations;
    ++stats_.live_buffers;
    stats_.bytes += bytes;
    return buffer;
}

void Renderer::release_buffer(unsigned& buffer, std::size_t bytes) {
    if (!buffer) return;
    glDeleteBuffers(1, &buffer);
    buffer = 0;
    --stats_.live_buffers;
    stats_.bytes -= bytes;
}

void Renderer::release_scene() {
    for (ObjectBuffers& o : objects_) {
        release_buffer(o.positions, o.vertex_bytes);
        release_buffer(o.surface_indices, o.surface_capacity * sizeof(std::uint32_t));
        glDeleteVertexArrays(1, &o.surface_array);
        for (Region* region : {&o.highlight, &o.margin, &o.located}) {
            release_buffer(region->indices, region->capacity * sizeof(std::uint32_t));
            glDeleteVertexArrays(1, &region->array);
        }
    }
    objects_.clear();
}

void Renderer::load_scene(const ViewSession& session) {
    release_scene();
    const Scene& scene = session.scene();
    Bounds box;
    for (std::size_t o = 0; o < scene.num_objects(); ++o) {
        ObjectBuffers b;
        const TetMesh& mesh = scene.rest_mesh(o);
        const std::vector<std::uint32_t>& surface = session.faces()[o].boundary;
        b.vertex_bytes = mesh.num_vertices() * 3 * sizeof(float);
        b.surface_count = b.surface_capacity = surface.size();
        glGenVertexArrays(1, &b.surface_array);
        glBindVertexArray(b.surface_array);
        b.positions = make_buffer(GL_ARRAY_BUFFER, b.vertex_bytes, nullptr, GL_DYNAMIC_DRAW);
        glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
        glEnableVertexAttribArray(0);
        b.surface_indices = make_buffer(GL_ELEMENT_ARRAY_BUFFER, surface.size() * sizeof(std::uint32_t),
                                        surface.data(), GL_STATIC_DRAW);
        for (Region* region : {&b.highlight, &b.margin, &b.located}) {
            glGenVertexArrays(1, &region->array);
            glBindVertexArray(region->array);
            glBindBuffer(GL_ARRAY_BUFFER, b.positions);
            glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
            glEnableVertexAttribArray(0);
        }
        objects_.push_back(b);
        for (std::size_t i = 0; i < mesh.positions.size(); i += 3)
            box.add(Vec3{static_cast<float>(mesh.positions[i]), static_cast<float>(mesh.positions[i + 1]),
                         static_cast<float>(mesh.positions[i + 2])});
    }
    glBindVertexArray(0);
    scene_radius_ = std::max(box.radius(), 1e-6f);
    scene_version_ = session.scene_version();
    topology_version_ = session.topology_version();
    positions_version_ = result_version_ = 0;
    contacts_.vertices = selection_.vertices = points_.vertices = 0;
    point_counts_ = {};
}

void Renderer::update(const ViewSession& session) {
    if (session.scene_version() != scene_version_) load_scene(session);
    if (session.topology_version() != topology_version_) upload_surfaces(session);
    if (session.positions_version() != positions_version_) {
        for (std::size_t o = 0; o < objects_.size(); ++o) {
            const std::vector<float>& xyz = session.positions()[o];
            glBindBuffer(GL_ARRAY_BUFFER, objects_[o].positions);
            glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(xyz.size() * sizeof(float)), xyz.data());
            ++stats_.position_uploads;
        }
        positions_version_ = session.positions_version();
    }
    if (session.has_result() && session.result_version() != result_version_) {
        upload_highlights(session);
        upload_contacts(session);
        upload_points(session);
        result_version_ = session.result_version();
    }
}

void Renderer::upload_surfaces(const ViewSession& session) {
    for (std::size_t o = 0; o < objects_.size(); ++o) {
        ObjectBuffers& b = objects_[o];
        const std::vector<std::uint32_t>& surface = session.faces()[o].boundary;
        b.surface_count = surface.size();
        if (b.surface_count == 0) continue;
        glBindVertexArray(b.surface_array);
        if (b.surface_count > b.surface_capacity) {
            // A tear adds boundary faces a few at a time: grown geometrically, it is rarely remade.
            release_buffer(b.surface_indices, b.surface_capacity * sizeof(std::uint32_t));
            b.surface_capacity = std::max(b.surface_count, 2 * b.surface_capacity);
            b.surface_indices = make_buffer(GL_ELEMENT_ARRAY_BUFFER, b.surface_capacity * sizeof(std::uint32_t), nullptr,
                                            GL_STATIC_DRAW);
        }
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, b.surface_indices);
        glBufferSubData(GL_ELEMENT_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(b.surface_count * sizeof(std::uint32_t)),
                        surface.data());
        glBindVertexArray(0);
    }
    topology_version_ = session.topology_version();
}

void Renderer::upload_highlights(const ViewSession& session) {
    const FrameResult& result = session.result();
    const std::vector<std::vector<std::uint8_t>>& margin = session.margin_tets();
    for (std::size_t o = 0; o < objects_.size(); ++o) {
        // A tet within the margin only is drawn in its own colour, not as colliding.
        std::vector<std::uint8_t> colliding = o < result.colliding.size() ? result.colliding[o] : std::vector<std::uint8_t>{};
        if (o < margin.size())
            for (std::size_t t = 0; t < colliding.size(); ++t) colliding[t] = colliding[t] && !margin[o][t];
        upload_region(session, o, objects_[o].highlight, colliding);
        upload_region(session, o, objects_[o].margin, o < margin.size() ? margin[o] : std::vector<std::uint8_t>{});
    }
}

void Renderer::upload_region(const ViewSession& session, std::size_t object, Region& region,
                             const std::vector<std::uint8_t>& flags) {
    scratch_indices_.clear();
    // Faces between two flagged tets are hidden inside the region: only its surface is drawn.
    if (!flags.empty()) append_flagged_region(session.mesh(object), session.faces()[object], flags, scratch_indices_);
    region.count = scratch_indices_.size();
    if (region.count == 0) return;
    if (region.count > region.capacity) {
        // Grown geometrically, so that an animation allocates a few times at most.
        release_buffer(region.indices, region.capacity * sizeof(std::uint32_t));
        region.capacity = std::max(region.count, 2 * region.capacity);
        glBindVertexArray(region.array);
        region.indices = make_buffer(GL_ELEMENT_ARRAY_BUFFER, region.capacity * sizeof(std::uint32_t), nullptr, GL_DYNAMIC_DRAW);
        glBindVertexArray(0);
    }
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, region.indices);
    glBufferSubData(GL_ELEMENT_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(region.count * sizeof(std::uint32_t)),
                    scratch_indices_.data());
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, 0);
}

void Renderer::select_point(const ViewSession& session, std::optional<std::size_t> point) {
    selected_point_ = point;
    upload_points(session);
}

void Renderer::upload_points(const ViewSession& session) {
    const LocateResult& located = session.located();
    // A selected point is drawn alone with its tets: among many points they would be hidden.
    const bool one = selected_point_ && *selected_point_ < located.point_count;
    std::vector<std::vector<std::uint8_t>> holding(objects_.size());
    for (std::size_t o = 0; o < objects_.size(); ++o)
        if (located.point_count > 0) holding[o].assign(session.mesh(o).num_tets(), 0);
    const std::uint64_t first = one ? located.offsets[*selected_point_] : 0;
    const std::uint64_t last = one ? located.offsets[*selected_point_ + 1] : located.hit_count;
    for (std::uint64_t h = first; h < last; ++h)
        if (one || located.distances[h] == 0) holding[located.objects[h]][located.tets[h]] = 1;
    for (std::size_t o = 0; o < objects_.size(); ++o) upload_region(session, o, objects_[o].located, holding[o]);
    // Grouped by status, so that each group is one draw call in its colour; the held points last,
    // over the others.
    scratch_vertices_.clear();
    const std::vector<double>& xyz = session.points();
    for (int status = 2; status >= 0; --status) {
        const std::size_t before = scratch_vertices_.size();
        for (std::size_t p = one ? *selected_point_ : 0; p < (one ? *selected_point_ + 1 : located.point_count); ++p)
            if (point_status(located, p) == status)
                scratch_vertices_.insert(scratch_vertices_.end(), {static_cast<float>(xyz[3 * p]), static_cast<float>(xyz[3 * p + 1]),
                                                                   static_cast<float>(xyz[3 * p + 2]), 0, 0, 0});
        point_counts_[static_cast<std::size_t>(status)] = (scratch_vertices_.size() - before) / 6;
    }
    upload_stream(points_, scratch_vertices_);
}

void Renderer::upload_contacts(const ViewSession& session) {
    const FrameResult& result = session.result();
    scratch_vertices_.clear();
    if (!result.contacts.empty()) {
        const auto centroid = [&](std::uint32_t object, std::uint32_t tet, int axis) {
            const std::uint32_t* v = &session.mesh(object).tets[4 * static_cast<std::size_t>(tet)];
            const std::vector<float>& p = session.positions()[object];
            return 0.25f * (p[3 * v[0] + axis] + p[3 * v[1] + axis] + p[3 * v[2] + axis] + p[3 * v[3] + axis]);
        };
        // Per pair two vertices (base, offset): the midpoint of the two tets' centroids, then the
        // same point pushed along the direction that separates them. Deep overlaps have tens of
        // thousands of pairs: an even sample of them stays readable.
        const std::size_t pairs = std::min(result.pairs.size(), result.contacts.size());
        const std::size_t stride = (pairs + max_contact_lines - 1) / max_contact_lines;
        for (std::size_t k = 0; k < pairs; k += stride) {
            const TetPair& p = result.pairs[k];
            float base[3];
            for (int a = 0; a < 3; ++a) base[a] = 0.5f * (centroid(p.object_a, p.tet_a, a) + centroid(p.object_b, p.tet_b, a));
            const float* d = result.contacts[k].direction;
            scratch_vertices_.insert(scratch_vertices_.end(), {base[0], base[1], base[2], 0, 0, 0});
            scratch_vertices_.insert(scratch_vertices_.end(), {base[0], base[1], base[2], d[0], d[1], d[2]});
        }
    }
    upload_stream(contacts_, scratch_vertices_);
}

void Renderer::upload_stream(Stream& stream, const std::vector<float>& vertices) {
    stream.vertices = vertices.size() / 6;
    if (stream.vertices == 0) return;
    glBindVertexArray(stream.array);
    if (vertices.size() > stream.capacity) {
        release_buffer(stream.buffer, stream.capacity * sizeof(float));
        stream.capacity = std::max(vertices.size(), 2 * stream.capacity);
        stream.buffer = make_buffer(GL_ARRAY_BUFFER, stream.capacity * sizeof(float), nullptr, GL_DYNAMIC_DRAW);
        glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
        glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), reinterpret_cast<const void*>(3 * sizeof(float)));
        glEnableVertexAttribArray(0);
        glEnableVertexAttribArray(1);
    }
    glBindBuffer(GL_ARRAY_BUFFER, stream.buffer);
    glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(vertices.size() * sizeof(float)), vertices.data());
    glBindVertexArray(0);
}

void Renderer::select(const ViewSession& session, const std::vector<TetRef>& tets) {
    // Every face of every tet as its own triangle; the first tet is the selected one.
    scratch_vertices_.clear();
    for (const TetRef& ref : tets) {
        if (ref.object >= session.positions().size()) continue;
        const std::uint32_t* v = &session.mesh(ref.object).tets[4 * static_cast<std::size_t>(ref.tet)];
        const std::vector<float>& p = session.positions()[ref.object];
        for (const auto& corners : tet_face_vertices)
            for (const int c : corners) {
                const std::size_t i = 3 * static_cast<std::size_t>(v[c]);
                scratch_vertices_.insert(scratch_vertices_.end(), {p[i], p[i + 1], p[i + 2], 0, 0, 0});
            }
    }
    upload_stream(selection_, scratch_vertices_);
}

void Renderer::draw_objects(bool surfaces, Region ObjectBuffers::*region) const {
    for (std::size_t o = 0; o < objects_.size(); ++o) {
        const ObjectBuffers& b = objects_[o];
        if (surfaces && b.surface_count) {
            glBindVertexArray(b.surface_array);
            glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(b.surface_count), GL_UNSIGNED_INT, nullptr);
        }
        if (region && (b.*region).count) {
            glBindVertexArray((b.*region).array);
            glDrawElements(GL_TRIANGLES, static_cast<GLsizei>((b.*region).count), GL_UNSIGNED_INT, nullptr);
        }
    }
    glBindVertexArray(0);
}

void Renderer::draw(const OrbitCamera& camera, int x, int y, int width, int height, const DisplaySettings& display,
                    const Bounds& scene_box) const {
    glViewport(x, y, width, height);
    glEnable(GL_SCISSOR_TEST);
    glScissor(x, y, width, height);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    glUseProgram(background_program_);
    glBindVertexArray(empty_array_);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glClear(GL_DEPTH_BUFFER_BIT);

    const float aspect = static_cast<float>(width) / static_cast<float>(std::max(height, 1));
    const Mat4 view = camera.view(), projection = camera.projection(aspect);
    glUseProgram(mesh_program_);
    glUniformMatrix4fv(uniform(mesh_program_, "view"), 1, GL_FALSE, view.m.data());
    glUniformMatrix4fv(uniform(mesh_program_, "projection"), 1, GL_FALSE, projection.m.data());
    glUniform1f(uniform(mesh_program_, "offset_scale"), 0.0f);
    glVertexAttrib3f(1, 0.0f, 0.0f, 0.0f);
    const std::array<float, 4> plane = clip_plane(display, scene_box);
    if (display.clip) {
        glEnable(GL_CLIP_DISTANCE0);
    } else {
        glDisable(GL_CLIP_DISTANCE0);
    }
    glUniform4fv(uniform(mesh_program_, "clip_plane"), 1, plane.data());

    const GLint lit = uniform(mesh_program_, "lit"), back = uniform(mesh_program_, "shade_back_faces");
    const bool translucent = display.surface_opacity < 1.0f && !display.only_colliding;
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
    glUniform1i(lit, 1);

    // Surfaces first. Opaque ones fill the depth buffer, so colliding tets show where they are
    // exposed (or cut open by the clipping plane). Translucent ones leave it empty, so the
    // colliding tets drawn next appear over them, interior ones included.
    if (!display.only_colliding) {
        glUniform1i(back, 1);
        if (translucent) {
            glEnable(GL_BLEND);
            glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
            glDepthMask(GL_FALSE);
            if (!display.clip) {
                glEnable(GL_CULL_FACE);
                glCullFace(GL_BACK);
            }
        } else if (display.wireframe) {
            glEnable(GL_POLYGON_OFFSET_FILL);
            glPolygonOffset(1.0f, 1.0f);
        }
        for (std::size_t o = 0; o < objects_.size(); ++o) {
            const ObjectBuffers& b = objects_[o];
            if (!b.surface_count) continue;
            set_color(mesh_program_, object_color(o), translucent ? display.surface_opacity : 1.0f);
            glBindVertexArray(b.surface_array);
            glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(b.surface_count), GL_UNSIGNED_INT, nullptr);
        }
        glDisable(GL_CULL_FACE);
        glDisable(GL_BLEND);
        glDepthMask(GL_TRUE);
        glDisable(GL_POLYGON_OFFSET_FILL);
    }

    // Colliding tets: faces they share with the surface are pulled forward so that they win.
    glUniform1i(back, 0);
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(display.wireframe ? 0.0f : -1.0f, display.wireframe ? 0.0f : -2.0f);
    set_color(mesh_program_, highlight_color(), 1.0f);
    draw_objects(false, &ObjectBuffers::highlight);
    set_color(mesh_program_, margin_color(), 1.0f);
    draw_objects(false, &ObjectBuffers::margin);
    set_color(mesh_program_, located_color(), 1.0f);
    draw_objects(false, &ObjectBuffers::located);
    glDisable(GL_POLYGON_OFFSET_FILL);

    if (display.wireframe) {
        glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
        glUniform1i(lit, 0);
        glEnable(GL_BLEND);
        glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
        if (!display.only_colliding) {
            if (translucent) {
                glEnable(GL_CULL_FACE);
                glCullFace(GL_BACK);
            }
            set_color(mesh_program_, Color{0.05f, 0.06f, 0.08f}, 0.55f);
            draw_objects(true, nullptr);
            glDisable(GL_CULL_FACE);
        }
        set_color(mesh_program_, scaled(highlight_color(), 0.4f), 1.0f);
        draw_objects(false, &ObjectBuffers::highlight);
        set_color(mesh_program_, scaled(margin_color(), 0.4f), 1.0f);
        draw_objects(false, &ObjectBuffers::margin);
        glDisable(GL_BLEND);
        glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
        glUniform1i(lit, 1);
    }

    if (selection_.vertices > 0) {
        // The tets the selected one collides with over everything else (they usually lie inside
        // other colliding tets), and the selected tet over them.
        glUniform1i(lit, 1);
        glBindVertexArray(selection_.array);
        glClear(GL_DEPTH_BUFFER_BIT);
        set_color(mesh_program_, partner_color(), 1.0f);
        glDrawArrays(GL_TRIANGLES, 12, static_cast<GLsizei>(selection_.vertices) - 12);
        glClear(GL_DEPTH_BUFFER_BIT);
        set_color(mesh_program_, selected_color(), 1.0f);
        glDrawArrays(GL_TRIANGLES, 0, 12);
        glBindVertexArray(0);
    }

    if (display.contact_normals && contacts_.vertices > 0) {
        glUniform1i(lit, 0);
        glUniform1f(uniform(mesh_program_, "offset_scale"), 0.05f * scene_radius_ * display.normal_length);
        set_color(mesh_program_, normal_color(), 1.0f);
        if (translucent) glDisable(GL_DEPTH_TEST);
        glBindVertexArray(contacts_.array);
        glDrawArrays(GL_LINES, 0, static_cast<GLsizei>(contacts_.vertices));
        glBindVertexArray(0);
        glEnable(GL_DEPTH_TEST);
    }

    if (points_.vertices > 0) {
        // Query points over everything, where they lie inside the meshes too.
        glDisable(GL_DEPTH_TEST);
        glUniform1i(lit, 0);
        glPointSize(5.0f);
        glBindVertexArray(points_.array);
        std::size_t first = 0;
        for (int status = 2; status >= 0; --status) {
            const std::size_t n = point_counts_[static_cast<std::size_t>(status)];
            set_color(mesh_program_, point_color(status), 1.0f);
            if (n) glDrawArrays(GL_POINTS, static_cast<GLint>(first), static_cast<GLsizei>(n));
            first += n;
        }
        glBindVertexArray(0);
    }

    glDisable(GL_CLIP_DISTANCE0);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_SCISSOR_TEST);
    glUseProgram(0);
}

OffscreenTarget::OffscreenTarget(int width, int height, int samples) : width_(width), height_(height), samples_(samples) {
    GLint max_samples = 1;
    glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
    samples_ = std::clamp(samples_, 1, std::max(max_samples, 1));
    const auto storage = [&](unsigned& buffer, GLenum format, int count) {
        glGenRenderbuffers(1, &buffer);
        glBindRenderbuffer(GL_RENDERBUFFER, buffer);
        if (count > 1) {
            glRenderbufferStorageMultisample(GL_RENDERBUFFER, count, format, width_, height_);
        } else {
            glRenderbufferStorage(GL_RENDERBUFFER, format, width_, height_);
        }
    };
    glGenFramebuffers(1, &resolve_framebuffer_);
    glBindFramebuffer(GL_FRAMEBUFFER, resolve_framebuffer_);
    storage(resolved_color_, GL_RGBA8, 1);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, resolved_color_);
    glGenFramebuffers(1, &draw_framebuffer_);
    glBindFramebuffer(GL_FRAMEBUFFER, draw_framebuffer_);
    storage(color_, GL_RGBA8, samples_);
    storage(depth_, GL_DEPTH24_STENCIL8, samples_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, depth_);
    const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (status != GL_FRAMEBUFFER_COMPLETE)
        throw Error("view: the OpenGL driver cannot make a " + std::to_string(width_) + "x" + std::to_string(height_) +
                    " framebuffer with " + std::to_string(samples_) + " samples");
}

OffscreenTarget::~OffscreenTarget() {
    glDeleteFramebuffers(1, &draw_framebuffer_);
    glDeleteFramebuffers(1, &resolve_framebuffer_);
    glDeleteRenderbuffers(1, &color_);
    glDeleteRenderbuffers(1, &depth_);
    glDeleteRenderbuffers(1, &resolved_color_);
}

void OffscreenTarget::bind() const {
    glBindFramebuffer(GL_FRAMEBUFFER, draw_framebuffer_);
    glViewport(0, 0, width_, height_);
}

std::vector<std::uint8_t> OffscreenTarget::read_rgb() const {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, draw_framebuffer_);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_framebuffer_);
    glBlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, resolve_framebuffer_);
    std::vector<std::uint8_t> rgb = read_framebuffer_rgb(0, 0, width_, height_);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    return rgb;
}

std::vector<std::uint8_t> read_framebuffer_rgb(int x, int y, int width, int height) {
    const std::size_t row = static_cast<std::size_t>(width) * 3;
    std::vector<std::uint8_t> bottom_up(row * static_cast<std::size_t>(height)), rgb(bottom_up.size());
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(x, y, width, height, GL_RGB, GL_UNSIGNED_BYTE, bottom_up.data());
    for (int r = 0; r < height; ++r)
        std::copy_n(bottom_up.begin() + static_cast<std::ptrdiff_t>(row * static_cast<std::size_t>(height - 1 - r)), row,
                    rgb.begin() + static_cast<std::ptrdiff_t>(row * static_cast<std::size_t>(r)));
    return rgb;
}

} // namespace kdet::view
