// Lookups in the library's small constant tables whose entries carry a name
// (channel kinds, normalization modes, bone roles). `key` points at the
// entry's name or enum member, so one lookup serves every table.
#pragma once

#include <cassert>
#include <cstddef>
#include <span>
#include <string>
#include <string_view>

namespace mmvk::detail {

// The entry of `table` whose name is `name`, or nullptr.
template <class Entry>
const Entry* find_named(std::span<const Entry> table, std::string_view Entry::*key, std::string_view name) {
  for (const Entry& entry : table) {
    if (entry.*key == name) return &entry;
  }
  return nullptr;
}

// The names of `table` for an error message: "a", "b", ... with `quote`
// around each (or `quote` before each when `quote_after` is false).
template <class Entry>
std::string name_list(std::span<const Entry> table, std::string_view Entry::*key, char quote, bool quote_after) {
  std::string list;
  for (const Entry& entry : table) {
    if (!list.empty()) list += ", ";
    list += quote;
    list += entry.*key;
    if (quote_after) list += quote;
  }
  return list;
}

// True when entry i of `table` is for enum value i, so the table can be
// indexed by the enum.
template <class Entry, class Enum>
constexpr bool indexed_by(std::span<const Entry> table, Enum Entry::*key) {
  for (std::size_t i = 0; i < table.size(); ++i) {
    if (static_cast<std::size_t>(table[i].*key) != i) return false;
  }
  return true;
}

// The entry for `value` of a table indexed by its enum (see indexed_by).
template <class Entry, class Enum>
const Entry& entry_for(std::span<const Entry> table, Enum value) {
  // A value outside the enum is a caller's bug: JSON and database files
  // name their kinds and modes, and are parsed by name.
  assert(static_cast<std::size_t>(value) < table.size());
  return table[static_cast<std::size_t>(value)];
}

// The name of `value`, or "?" for a value outside the table.
template <class Entry, class Enum>
std::string_view name_for(std::span<const Entry> table, std::string_view Entry::*key, Enum value) {
  const auto index = static_cast<std::size_t>(value);
  return index < table.size() ? table[index].*key : std::string_view("?");
}

}  // namespace mmvk::detail
