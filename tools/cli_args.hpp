#pragma once
/// @file cli_args.hpp
/// @brief A small command-line parser that turns every mistake into a one-line UsageError.

#include <kdet/options.hpp>

#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace kdet::cli {

/// @brief A mistake on the command line; the message names the flag and what it accepts.
class UsageError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// @brief Declares flags and positional arguments, then parses argv against them.
class ArgParser {
public:
    explicit ArgParser(std::string command) : command_(std::move(command)) {}

    /// @brief A flag without a value, e.g. --self.
    void flag(const std::string& name, std::function<void()> on_seen);
    /// @brief A flag followed by a value, e.g. --threads 4 (or --threads=4 for long flags).
    void option(const std::string& name, const std::string& value_name, std::function<void(const std::string&)> on_value);
    /// @brief Collects positional arguments; more than `max_count` is an error.
    void positionals(std::size_t max_count, std::vector<std::string>& out);

    void parse(int argc, char** argv, int first) const;

    const std::string& command() const { return command_; }

private:
    struct Spec {
        std::string name, value_name;
        std::function<void()> on_flag;
        std::function<void(const std::string&)> on_value;
    };
    const Spec* find(const std::string& name) const;

    std::string command_;
    std::vector<Spec> specs_;
    std::size_t max_positionals_ = 0;
    std::vector<std::string>* positionals_ = nullptr;
};

/// @brief Parses a whole decimal integer in [lo, hi] or throws a UsageError naming `flag`.
long long parse_integer(const std::string& flag, const std::string& text, long long lo, long long hi);

/// @brief Parses one of `accepted` (the error lists them all).
std::string parse_choice(const std::string& flag, const std::string& text, const std::vector<std::string>& accepted);

/// @brief Joins names for error messages: "a, b or c".
std::string join_choices(const std::vector<std::string>& names);

/// @brief Reads the value of an option flag (a Backend, Method, NarrowPhase or HashFunction) with the
/// library's names (kdet::parse: any case, '-' or '_'), or throws a UsageError that lists them.
template <class Option>
Option parse_option(const std::string& flag, const std::string& text) {
    Option value{};
    if (!kdet::parse(text, value))
        throw UsageError("invalid value '" + text + "' for " + flag + ": expected " + join_choices(option_names<Option>()));
    return value;
}

/// @brief "a (default), b, c": the names of an option type for help texts, the default marked.
template <class Option>
std::string option_help(Option default_value) {
    std::string out;
    for (const std::string& name : option_names<Option>()) {
        if (!out.empty()) out += ", ";
        out += name;
        if (name == to_string(default_value)) out += " (default)";
    }
    return out;
}

} // namespace kdet::cli
