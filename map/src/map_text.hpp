// map_text.hpp — printf into a std::string: the map's messages and its checkpoint's
// fingerprint (map_points.cpp, map_output.cpp), in the bytes printf writes.
#pragma once

#include <cstdio>
#include <string>

namespace backlash::map::detail {

template <class... Arguments>
void appendf(std::string& out, const char* format, Arguments... arguments) {
  const int length = std::snprintf(nullptr, 0, format, arguments...);
  if (length <= 0) return;
  const std::size_t start = out.size(), size = static_cast<std::size_t>(length);
  out.resize(start + size + 1);
  std::snprintf(out.data() + start, size + 1, format, arguments...);
  out.resize(start + size);
}

}  // namespace backlash::map::detail
