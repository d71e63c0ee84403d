// KeptByBits's key and LinearReferenceCache (reference.hpp): reference integrations kept by their
// exact inputs.
#include "backlash/numeric/reference.hpp"

namespace backlash::numeric {

void append_bits(std::string& key, const double* values, std::size_t n) {
  key.append(reinterpret_cast<const char*>(values), n * sizeof(double));
}

std::vector<SmallVector> LinearReferenceCache::trajectory(const LinearSegment& segment, const SmallVector& z0,
                                                          const std::vector<double>& times, double tolerance) {
  // The sizes, then the bits of A, c, z0, the times and the tolerance.
  const Eigen::Index sizes[] = {segment.A.rows(), segment.A.cols(), segment.c.size(), z0.size(),
                                static_cast<Eigen::Index>(times.size())};
  std::string key(reinterpret_cast<const char*>(sizes), sizeof sizes);
  append_bits(key, segment.A.data(), static_cast<std::size_t>(segment.A.size()));
  append_bits(key, segment.c.data(), static_cast<std::size_t>(segment.c.size()));
  append_bits(key, z0.data(), static_cast<std::size_t>(z0.size()));
  append_bits(key, times.data(), times.size());
  append_bits(key, &tolerance, 1);
  return kept_.get(std::move(key), [&] { return reference_linear_trajectory(segment, z0, times, tolerance); });
}

}  // namespace backlash::numeric
