#include "cli_args.hpp"

#include <cerrno>
#include <cstdlib>

namespace kdet::cli {

void ArgParser::flag(const std::string& name, std::function<void()> on_seen) {
    specs_.push_back(Spec{name, "", std::move(on_seen), nullptr});
}

void ArgParser::option(const std::string& name, const std::string& value_name,
                       std::function<void(const std::string&)> on_value) {
    specs_.push_back(Spec{name, value_name, nullptr, std::move(on_value)});
}

void ArgParser::positionals(std::size_t max_count, std::vector<std::string>& out) {
    max_positionals_ = max_count;
    positionals_ = &out;
}

const ArgParser::Spec* ArgParser::find(const std::string& name) const {
    for (const Spec& s : specs_)
        if (s.name == name) return &s;
    return nullptr;
}

void ArgParser::parse(int argc, char** argv, int first) const {
    bool only_positionals = false;
    for (int i = first; i < argc; ++i) {
        std::string arg = argv[i];
        if (only_positionals || arg.size() < 2 || arg[0] != '-' || arg == "-") {
            if (!positionals_ || positionals_->size() >= max_positionals_)
                throw UsageError(command_ + ": unexpected argument '" + arg + "'");
            positionals_->push_back(arg);
            continue;
        }
        if (arg == "--") {
            only_positionals = true;
            continue;
        }
        std::string inline_value;
        bool has_inline_value = false;
        const auto equals = arg.find('=');
        if (arg.rfind("--", 0) == 0 && equals != std::string::npos) {
            inline_value = arg.substr(equals + 1);
            arg = arg.substr(0, equals);
            has_inline_value = true;
        }
        const Spec* spec = find(arg);
        if (!spec) throw UsageError(command_ + ": unknown option '" + arg + "' (see '" + command_ + " --help')");
        if (spec->on_flag) {
            if (has_inline_value) throw UsageError(command_ + ": option '" + arg + "' takes no value");
            spec->on_flag();
            continue;
        }
        if (!has_inline_value) {
            if (i + 1 >= argc) throw UsageError(command_ + ": option '" + arg + "' needs a value <" + spec->value_name + ">");
            inline_value = argv[++i];
        }
        spec->on_value(inline_value);
    }
}

long long parse_integer(const std::string& flag, const std::string& text, long long lo, long long hi) {
    errno = 0;
    char* end = nullptr;
    const long long value = std::strtoll(text.c_str(), &end, 10);
    if (text.empty() || *end != '\0' || errno == ERANGE || value < lo || value > hi)
        throw UsageError("invalid value '" + text + "' for " + flag + ": expected an integer in [" + std::to_string(lo) +
                         ", " + std::to_string(hi) + "]");
    return value;
}

std::string join_choices(const std::vector<std::string>& names) {
    std::string out;
    for (std::size_t i = 0; i < names.size(); ++i) {
        if (i) out += i + 1 == names.size() ? " or " : ", ";
        out += names[i];
    }
    return out;
}

std::string parse_choice(const std::string& flag, const std::string& text, const std::vector<std::string>& accepted) {
    for (const std::string& a : accepted)
        if (a == text) return text;
    throw UsageError("invalid value '" + text + "' for " + flag + ": expected " + join_choices(accepted));
}

} // namespace kdet::cli
