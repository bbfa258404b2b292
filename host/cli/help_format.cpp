#include "help_format.hpp"

#include <algorithm>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

namespace mmvk::cli {

namespace {

// Appends `line` wrapped at `width` to `out`; continuation lines start with
// `indent` spaces.
void wrap_line(std::string& out, std::string line, std::string_view words, std::size_t indent, std::size_t width) {
  bool fresh = true;  // no word on this line yet
  while (!words.empty()) {
    const std::size_t space = words.find(' ');
    const std::string_view word = words.substr(0, space);
    words = space == std::string_view::npos ? std::string_view() : words.substr(space + 1);
    if (word.empty()) continue;
    if (!fresh && line.size() + 1 + word.size() > width) {
      out += line + "\n";
      line.assign(indent, ' ');
      fresh = true;
    }
    if (!fresh) line += ' ';
    line.append(word);
    fresh = false;
  }
  out += line + "\n";
}

std::vector<std::string_view> split_lines(std::string_view text) {
  std::vector<std::string_view> lines;
  while (!text.empty()) {
    const std::size_t end = text.find('\n');
    lines.push_back(text.substr(0, end));
    text = end == std::string_view::npos ? std::string_view() : text.substr(end + 1);
  }
  return lines;
}

// "-o, --output FILE"; a flag has no value name.
std::string option_label(const CLI::Option& option) {
  std::string label;
  for (const std::string& name : option.get_snames()) label += (label.empty() ? "-" : ", -") + name;
  for (const std::string& name : option.get_lnames()) label += (label.empty() ? "--" : ", --") + name;
  if (!option.get_type_name().empty()) label += " " + option.get_type_name();
  return label;
}

class HelpFormatter : public CLI::FormatterBase {
 public:
  explicit HelpFormatter(std::string usage) : usage_(std::move(usage)) {}

  std::string make_help(const CLI::App* app, std::string, CLI::AppFormatMode) const override {
    std::string out = "usage: " + usage_ + "\n";
    if (!app->get_description().empty()) out += "\n" + wrap_text(app->get_description(), 80);
    for (const std::string& group : app->get_groups()) {
      const std::vector<const CLI::Option*> options = app->get_options(
          [&group](const CLI::Option* option) { return option->get_group() == group && option->nonpositional(); });
      if (group.empty() || options.empty()) continue;
      out += "\n" + group + ":\n";
      for (const CLI::Option* option : options) out += help_entry(option_label(*option), option->get_description());
    }
    std::string footer = app->get_footer();
    footer.erase(footer.find_last_not_of('\n') + 1);
    if (!footer.empty()) out += "\n" + footer + "\n";
    return out;
  }

 private:
  std::string usage_;
};

}  // namespace

std::string help_entry(std::string_view name, std::string_view description, std::size_t indent, std::size_t width) {
  std::string out;
  // Appending, not "  " + std::string(...): GCC 12 at -O3 warns (-Wrestrict,
  // a known false positive) on the latter.
  std::string line("  ");
  line.append(name);
  if (line.size() + 2 > indent) {
    out += line + "\n";
    line.clear();
  }
  line.resize(indent, ' ');
  for (const std::string_view part : split_lines(description)) {
    wrap_line(out, line, part, indent, width);
    line.assign(indent, ' ');
  }
  if (description.empty()) out += line.substr(0, line.find_last_not_of(' ') + 1) + "\n";
  return out;
}

std::string wrap_text(std::string_view text, std::size_t width) {
  std::string out;
  for (const std::string_view line : split_lines(text)) {
    const std::size_t indent = std::min(line.find_first_not_of(' '), line.size());
    if (indent > 0) {
      out.append(line).append("\n");  // an example, laid out by hand
    } else {
      wrap_line(out, std::string(), line, 0, width);
    }
  }
  return out;
}

std::shared_ptr<CLI::FormatterBase> make_help_formatter(std::string usage) {
  return std::make_shared<HelpFormatter>(std::move(usage));
}

}  // namespace mmvk::cli
