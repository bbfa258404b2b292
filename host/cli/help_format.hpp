// The layout of the subcommands' help: a usage line, a description, the
// options by group ("  NAME  description", word-wrapped) and a footer.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <string_view>

namespace CLI {
class FormatterBase;
}  // namespace CLI

namespace mmvk::cli {

// Descriptions start at this column and lines end by kHelpWidth.
inline constexpr std::size_t kHelpIndent = 24;
inline constexpr std::size_t kHelpWidth = 88;

// "  NAME  description": the description word-wrapped from column `indent`
// (on the next line when NAME reaches it); a '\n' in it starts a new line.
std::string help_entry(std::string_view name, std::string_view description, std::size_t indent = kHelpIndent,
                       std::size_t width = kHelpWidth);

// `text` word-wrapped at `width`; its own line breaks are kept, and a line
// that starts with a space (an example) is kept as it is.
std::string wrap_text(std::string_view text, std::size_t width);

// The formatter of a CLI::App: `usage` is the line after "usage: ".
std::shared_ptr<CLI::FormatterBase> make_help_formatter(std::string usage);

}  // namespace mmvk::cli
