#pragma once
/// @file option_table.hpp
/// @brief One descriptor per DetectorOptions field a user sets: its names on every front end, its
/// values, its help, and how to read and write it. The command line, `kdet bench`, the viewer's panel
/// and the Python package are all built from this table, so a new option is one entry here.
///
/// Messages are written here once. A value given as text (a flag's argument, a Python name) that is
/// refused reads "invalid value 'TEXT' for NAME: expected WHAT", NAME being the flag or keyword the
/// caller used. A number given as a number (Python keywords) that is out of range reads as
/// OptionInfo::set_number says, above the range as the Detector words its own checks.

#include <kdet/options.hpp>

#include <string>
#include <vector>

namespace kdet {

/// @brief The kind of value an option holds.
enum class OptionType {
    choice,  ///< one of a list of names (Backend, Method, NarrowPhase, HashFunction)
    integer, ///< a whole number in [min, max]
    boolean, ///< true or false
    real,    ///< a finite number >= 0 (a distance), stored as a float
};

/// @brief The front ends that show an option (a bit set).
enum FrontEnd : unsigned {
    front_end_cli = 1u << 0,    ///< `kdet collide` (long flag)
    front_end_bench = 1u << 1,  ///< `kdet bench` (its thesis flag where it has one, else the long flag)
    front_end_view = 1u << 2,   ///< `kdet view`'s command line (long flag)
    front_end_panel = 1u << 3,  ///< the viewer's side panel
    front_end_python = 1u << 4, ///< a keyword of kdet.Detector and the key of Detector.options
    front_end_locate = 1u << 5, ///< `kdet locate` (long flag): the options point location reads
};

/// @brief One option of DetectorOptions as every front end sees it.
struct OptionInfo {
    const char* name;       ///< canonical name: Python keyword, key of Detector.options and of --json
    const char* field;      ///< the DetectorOptions member it sets
    const char* flag;       ///< long flag of `kdet collide` and `kdet view` ("--test")
    const char* bench_flag; ///< `kdet bench`'s flag: the thesis's short flag ("-o") where it has one
    const char* label;      ///< words for people: the panel's label and range messages ("narrow phase")
    const char* value_name; ///< placeholder of the value in help texts ("T", "N")
    const char* help;       ///< one line: what it does (the choices and the default are added)
    OptionType type;
    long long min, max;     ///< integer: accepted range; a default outside it means "unset" (Python None)
    const char* zero_means; ///< integer whose range starts at 0: what 0 asks for ("chosen from the scene")
    unsigned front_ends;    ///< FrontEnd bits
    /// @brief The value in @p options: a choice's index in names(), an integer, 0/1, or a real's float
    /// bits (real() reads it as a number).
    long long (*get)(const DetectorOptions& options);
    /// @brief Stores @p value (as get() returns it) without checking it.
    void (*put)(DetectorOptions& options, long long value);
    /// @brief choice: the canonical names in declaration order; null for other types.
    const std::vector<std::string>& (*names)();
    /// @brief choice: reads any accepted spelling (kdet::parse) into an index of names().
    bool (*read_name)(const std::string& text, long long& index);

    bool shown_on(FrontEnd front_end) const { return (front_ends & front_end) != 0; }
    /// @brief The value of @p options as text: a canonical name, a decimal number, true or false.
    std::string text(const DetectorOptions& options) const;
    /// @brief The value of a default DetectorOptions as text().
    std::string default_text() const;
    /// @brief What is accepted, as messages say it: "cpu or cuda", "an integer in [1, 1024]", "true or false".
    std::string expected() const;
    /// @brief For help texts: the choices with "(default)" after @p defaults' one; for numbers the range.
    std::string values_help(const DetectorOptions& defaults) const;
    /// @brief Reads @p text into @p options, or throws kdet::Error "invalid value 'TEXT' for SHOWN: expected
    /// WHAT" (@p shown: the flag or keyword the caller used). Names in any case, '-' or '_'.
    void parse(const std::string& text, DetectorOptions& options, const std::string& shown) const;
    /// @brief Stores a number given as a number (integer and boolean options), or throws kdet::Error:
    /// "NAME: expected a positive number, got VALUE" below the range (with what 0 means where 0 is
    /// accepted), "LABEL VALUE out of range [LO, HI]" above it.
    void set_number(DetectorOptions& options, long long value) const;
    /// @brief Whether the default lies outside [min, max]: an integer that is unset until given.
    bool unset_by_default() const;
    /// @brief A real option's value.
    double real(const DetectorOptions& options) const;
    /// @brief Stores a real option's value given as a number, or throws kdet::Error "NAME: expected a
    /// finite number >= 0, got VALUE" (also for a value beyond float's range).
    void set_real(DetectorOptions& options, double value) const;
};

/// @brief Every option, in the order help texts list them.
const std::vector<OptionInfo>& option_table();

/// @brief The option named @p name (canonical name, field or flag without dashes, any case, '-' or
/// '_'), or null.
const OptionInfo* find_option(const std::string& name);

/// @brief "a, b or c": names for messages and help.
std::string join_names(const std::vector<std::string>& names);

/// @brief Throws kdet::Error for a value of @p options that the table does not take, in the words of
/// its parse and set_* functions: a choice that is none of its names (an enum cast from an integer), an
/// integer outside its range (an unset default excepted), a real that is not finite and >= 0.
void check_options(const DetectorOptions& options);

/// @brief Reads a whole decimal integer in [lo, hi], or throws kdet::Error "invalid value 'TEXT' for
/// SHOWN: expected an integer in [lo, hi]".
long long parse_integer(const std::string& shown, const std::string& text, long long lo, long long hi);

/// @brief Reads a whole decimal number in [lo, hi] ("2", "-0.5", "1e-3"; not hex, inf, nan or blanks),
/// or throws kdet::Error "invalid value 'TEXT' for SHOWN: expected EXPECTED".
double parse_number(const std::string& shown, const std::string& text, double lo, double hi, const std::string& expected);

/// @brief Returns @p text when it is one of @p accepted (exactly), or throws kdet::Error "invalid value
/// 'TEXT' for SHOWN: expected a, b or c".
std::string parse_choice(const std::string& shown, const std::string& text, const std::vector<std::string>& accepted);

/// @brief The message of a refused value: "invalid value 'TEXT' for SHOWN: expected EXPECTED".
std::string invalid_value_message(const std::string& shown, const std::string& text, const std::string& expected);

} // namespace kdet
