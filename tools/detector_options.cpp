// The help lines of the detector's flags, from the library's option table.

#include "commands.hpp"

#include <algorithm>
#include <string>

namespace kdet::cli {

std::string option_help_line(const OptionInfo& o, FrontEnd front_end, const DetectorOptions& defaults) {
    std::string head = "  " + flag_of(o, front_end) + " " + o.value_name;
    head.resize(std::max<std::size_t>(head.size() + 1, 23), ' ');
    std::string text = o.help;
    if (o.type == OptionType::choice) text += (text.empty() ? "" : ": ") + o.values_help(defaults);
    for (std::size_t at = text.find('\n'); at != std::string::npos; at = text.find('\n', at + 1))
        text.insert(at + 1, std::string(23, ' '));
    return head + text + "\n";
}

std::string detector_options_help(FrontEnd front_end, const DetectorOptions& defaults) {
    std::string out;
    for (const OptionInfo& o : option_table())
        if (o.shown_on(front_end)) out += option_help_line(o, front_end, defaults);
    return out;
}

} // namespace kdet::cli
