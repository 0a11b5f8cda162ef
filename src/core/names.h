#pragma once
// Enumerations with names (as in scene files and on the command line): one table per
// enumeration, kept beside it, and one parse function over the table, so every setting
// is parsed once, in one place, with one message listing the valid names.
#include <cstddef>
#include <string>
#include <string_view>

#include "src/core/error.h"

namespace lvox {

template <class E>
struct Named {
  E value;
  std::string_view name;
};

// "a, b, c": the names of a table, for messages and --help.
template <class E, size_t N>
std::string namesOf(const Named<E> (&table)[N]) {
  std::string list;
  for (const Named<E>& n : table) list += (list.empty() ? "" : ", ") + std::string(n.name);
  return list;
}

// The value named `name`; otherwise throws InputError(file, field, "unknown <what> 'name'
// (valid names)").
template <class E, size_t N>
E parseNamed(std::string_view name, const Named<E> (&table)[N], std::string_view what,
             const std::string& file, const std::string& field) {
  for (const Named<E>& n : table)
    if (n.name == name) return n.value;
  throw InputError(
      file, field,
      "unknown " + std::string(what) + " '" + std::string(name) + "' (" + namesOf(table) + ")");
}

template <class E, size_t N>
std::string_view nameOf(E value, const Named<E> (&table)[N]) {
  for (const Named<E>& n : table)
    if (n.value == value) return n.name;
  return "?";
}

}  // namespace lvox
