#include "ctid/core/progress.hpp"

#include <utility>

namespace ctid {

namespace {
thread_local ProgressCallback g_callback;
}

ProgressScope::ProgressScope(ProgressCallback callback) : previous_(std::move(g_callback)) {
  g_callback = std::move(callback);
}

ProgressScope::~ProgressScope() { g_callback = std::move(previous_); }

bool report_progress(const char* stage, int iteration, double cost) {
  if (!g_callback) return true;
  return g_callback(ProgressEvent{stage, iteration, cost});
}

}  // namespace ctid
