#include "view_command.hpp"

#include "cli_args.hpp"
#include "commands.hpp"
#include "session.hpp"
#include "view_args.hpp"
#include "viewer.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/io.hpp>

#include <cstdio>
#include <iostream>

namespace kdet::cli {

int run_view(int argc, char** argv) {
    view::ViewConfig config = view::parse_view_args(argc, argv, 2);
    if (config.help) {
        std::cout << view::view_help();
        return exit_ok;
    }
    std::string reason;
    if (config.options.backend == Backend::cuda && !cuda_available(&reason))
        throw Error("view: --backend cuda is not available here: " + reason);
    config.options.contacts = view::wants_contacts(config.display, false);
    view::ViewSession session(config.source, config.options, config.self);
    if (!config.resolution_flag.empty())
        check_resolution_flag("view", config.resolution_flag, config.source.request.resolution, session.scene());
    session.set_exclusion_rings(config.exclusion_rings);
    if (!config.points.empty()) session.set_points(read_points(config.points), config.within);
    if (config.frame >= session.num_frames())
        throw UsageError("view: invalid value '" + std::to_string(config.frame) + "' for --frame: scene '" +
                         session.scene().name() + "' has frames 0 to " + std::to_string(session.num_frames() - 1));
    const bool headless = !config.screenshot.empty() || config.profile;
    view::Viewer viewer(session, config, !headless);
    if (!config.screenshot.empty()) {
        viewer.screenshot(config.screenshot, config.width, config.height, config.panel);
        const FrameResult& r = session.result();
        std::printf("wrote %s: frame %d of %s, ", config.screenshot.c_str(), session.frame(), session.scene().name().c_str());
        const auto pairs = static_cast<unsigned long long>(r.counts.colliding_pairs);
        const auto tets = static_cast<unsigned long long>(r.counts.colliding_tets);
        if (config.options.margin > 0.0f)
            std::printf("%llu pairs within the margin (%llu overlapping), %llu tets in a pair\n", pairs,
                        pairs - static_cast<unsigned long long>(session.margin_pairs()), tets);
        else
            std::printf("%llu colliding pairs, %llu colliding tets\n", pairs, tets);
        if (!config.points.empty()) {
            const view::PointCounts points = view::count_points(session.located());
            std::printf("points: %zu in a tet, %zu near one, %zu without\n", points.held, points.near, points.missed);
        }
        return exit_ok;
    }
    if (config.profile) {
        viewer.profile(config.width, config.height);
        return exit_ok;
    }
    viewer.run();
    return exit_ok;
}

} // namespace kdet::cli
