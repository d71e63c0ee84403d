// LinearReferenceCache (reference.hpp): the reference integrations of the effect modes kept by
// their exact inputs.
#include "backlash/numeric/reference.hpp"

namespace backlash::numeric {

namespace {

// The inputs as bytes: the sizes, then the bits of A, c, z0, the times and the tolerance.
std::string key_of(const LinearSegment& segment, const SmallVector& z0, const std::vector<double>& times, double tolerance) {
  const Eigen::Index sizes[] = {segment.A.rows(), segment.A.cols(), segment.c.size(), z0.size(),
                                static_cast<Eigen::Index>(times.size())};
  std::string key(reinterpret_cast<const char*>(sizes), sizeof sizes);
  auto append = [&key](const double* values, std::size_t n) {
    key.append(reinterpret_cast<const char*>(values), n * sizeof(double));
  };
  append(segment.A.data(), static_cast<std::size_t>(segment.A.size()));
  append(segment.c.data(), static_cast<std::size_t>(segment.c.size()));
  append(z0.data(), static_cast<std::size_t>(z0.size()));
  append(times.data(), times.size());
  append(&tolerance, 1);
  return key;
}

}  // namespace

std::vector<SmallVector> LinearReferenceCache::trajectory(const LinearSegment& segment, const SmallVector& z0,
                                                          const std::vector<double>& times, double tolerance) {
  std::string key = key_of(segment, z0, times, tolerance);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto found = kept_.find(key);
    if (found != kept_.end()) {
      ++hits_;
      return found->second;
    }
  }
  // Integrated outside the lock: two threads with the same inputs both integrate, to the same bits.
  std::vector<SmallVector> states = reference_linear_trajectory(segment, z0, times, tolerance);
  std::lock_guard<std::mutex> lock(mutex_);
  ++integrations_;
  if (capacity_ > 0 && kept_.emplace(key, states).second) {
    order_.push_back(std::move(key));
    if (order_.size() > capacity_) {
      kept_.erase(order_.front());
      order_.pop_front();
    }
  }
  return states;
}

long LinearReferenceCache::hits() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return hits_;
}

long LinearReferenceCache::integrations() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return integrations_;
}

}  // namespace backlash::numeric
