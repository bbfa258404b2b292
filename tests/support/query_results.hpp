// Reading what `mmvk query --out` wrote, for end-to-end CLI tests.
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace mmvk::test {

inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The result lines without the '#' comments (which name the backend), so
// two backends' files compare equal when their results are.
inline std::string result_lines(const std::filesystem::path& path) {
  std::istringstream in(read_text(path));
  std::string line, kept;
  while (std::getline(in, line)) {
    if (!line.empty() && line[0] != '#') kept += line + "\n";
  }
  return kept;
}

}  // namespace mmvk::test
