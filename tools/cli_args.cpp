#include "cli_args.hpp"

#include <cstdio>
#include <kdet/error.hpp>
#include <kdet/scenes.hpp>

#include <CLI/CLI.hpp>

#include <algorithm>

namespace kdet::cli {

CommandLine::CommandLine(std::string command)
    : command_(std::move(command)), app_(std::make_unique<CLI::App>(command_)) {
    app_->set_help_flag();
    // Unknown flags and surplus arguments are reported below in kdet's words, not CLI11's.
    app_->allow_extras();
}

CommandLine::~CommandLine() = default;

void CommandLine::flag(const std::string& name, bool& seen) { app_->add_flag(name, seen)->disable_flag_override(); }

void CommandLine::option(const std::string& name, const std::string& value_name,
                         std::function<void(const std::string&)> on_value) {
    // Each value when it is read, in the order given: the last one wins, a flag that collects (`kdet
    // prepare -r`) sees them all, and `kdet bench` knows which procedural-only flag came first. An empty
    // FILE is refused: an empty path reads as "not asked for", so the output asked for would silently not
    // be written.
    const std::string no_file = value_name == "FILE" ? "option '" + name + "' needs a value <FILE>" : "";
    app_->add_option(name, [on_value = std::move(on_value), no_file](const CLI::results_t& values) {
            for (const std::string& v : values) {
                if (v.empty() && !no_file.empty()) throw UsageError(no_file);
                on_value(v);
            }
            return true;
        })
        ->type_name(value_name)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
        ->trigger_on_parse();
}

void CommandLine::positionals(std::size_t max_count, std::vector<std::string>& out) {
    max_positionals_ = max_count;
    positionals_ = &out;
    app_->add_option("arguments", out)->expected(0, CLI::detail::expected_max_vector_size);
}

std::string flag_of(const OptionInfo& option, FrontEnd front_end) {
    return front_end == front_end_bench ? option.bench_flag : option.flag;
}

std::string hash_label(const DetectorOptions& options) {
    const bool grid = options.method == Method::kdet || options.method == Method::kdet_no_pairs;
    return grid ? to_string(options.hash) : "none";
}

void check_resolution_flag(const std::string& command, const std::string& flag, int requested, const Scene& scene) {
    if (scene.resolution() == requested) return;
    throw UsageError(command + ": invalid value '" + std::to_string(requested) + "' for " + flag + ": scene '" + scene.name() +
                     "' " +
                     (scene.resolution() == 0 ? std::string("has no resolution (its meshes are not built at one)")
                                              : "is built at resolution " + std::to_string(scene.resolution()) + " only"));
}

std::uint64_t overlapping_pairs(const FrameResult& result) {
    return static_cast<std::uint64_t>(std::count(result.distances.begin(), result.distances.end(), 0.0f));
}

void print_pair_counts(const DetectorOptions& options, std::uint64_t pairs, std::uint64_t tets, const std::uint64_t* overlapping) {
    const bool margin = options.margin > 0.0f;
    if (options.method != Method::kdet_no_pairs) {
        std::printf(margin ? "pairs in margin   %llu" : "colliding pairs   %llu", static_cast<unsigned long long>(pairs));
        if (margin && overlapping)
            std::printf(" (%llu overlapping, the rest apart)", static_cast<unsigned long long>(*overlapping));
        std::printf("\n");
    }
    std::printf(margin ? "tets in a pair    %llu\n" : "colliding tets    %llu\n", static_cast<unsigned long long>(tets));
}

void CommandLine::detector_options(DetectorOptions& options, FrontEnd front_end) {
    for (const OptionInfo& o : option_table()) {
        if (!o.shown_on(front_end)) continue;
        const std::string flag = flag_of(o, front_end);
        // A missing value is named as before: "<method>" for a name, "<N>" for a number.
        option(flag, o.type == OptionType::choice ? o.name : o.value_name,
               [&options, &o, flag](const std::string& v) { o.parse(v, options, flag); });
    }
}

void CommandLine::parse(int argc, char** argv, int first) {
    std::vector<std::string> args(argv + first, argv + argc);
    std::reverse(args.begin(), args.end()); // CLI11 takes them last first
    try {
        app_->parse(args);
    } catch (const CLI::ArgumentMismatch& e) {
        // CLI11 starts this message with the option's name (with or without its dashes), the one name
        // each of kdet's options has.
        const std::string what = e.what();
        const std::string name = what.substr(0, what.find_first_of(": "));
        const CLI::Option* option = nullptr;
        for (const char* dashes : {"", "-", "--"})
            if (!option) option = app_->get_option_no_throw(std::string(dashes) + name);
        if (!option) throw UsageError(command_ + ": " + what);
        const std::string shown = option->get_name();
        if (option->get_expected_max() == 0) throw UsageError(command_ + ": option '" + shown + "' takes no value");
        throw UsageError(command_ + ": option '" + shown + "' needs a value <" + option->get_type_name() + ">");
    } catch (const CLI::ParseError& e) {
        throw UsageError(command_ + ": " + e.what());
    } catch (const Error& e) {
        throw UsageError(command_ + ": " + e.what());
    } catch (const UsageError& e) {
        // From a value's own check, which does not know the command.
        throw UsageError(command_ + ": " + e.what());
    }
    // An unknown flag first: the value after it would otherwise read as a surplus argument.
    const std::vector<std::string> extras = app_->remaining();
    for (const std::string& extra : extras)
        if (extra.size() > 1 && extra[0] == '-' && extra != "--")
            throw UsageError(command_ + ": unknown option '" + extra.substr(0, extra.find('=')) + "' (see 'kdet " +
                             command_ + " --help')");
    if (positionals_ && positionals_->size() > max_positionals_)
        throw UsageError(command_ + ": unexpected argument '" + (*positionals_)[max_positionals_] + "'");
    for (const std::string& extra : extras)
        if (extra != "--") throw UsageError(command_ + ": unexpected argument '" + extra + "'");
}

} // namespace kdet::cli
