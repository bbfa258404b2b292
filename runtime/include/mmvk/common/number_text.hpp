// A number as error messages and help texts show it: printf's "%g" (six
// significant digits, no trailing zeros: "0.1", "30", "1e+30"), so a value
// reads the same in every message that names it.
#pragma once

#include <cstdio>
#include <string>

namespace mmvk {

inline std::string number_text(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", value);
  return text;
}

}  // namespace mmvk
