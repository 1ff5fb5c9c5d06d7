#include "ctid/core/status.hpp"

#include "ctid/core/check.hpp"

namespace ctid {

namespace {
constexpr std::pair<Termination, const char*> kNames[] = {
    {Termination::Completed, "completed"},         {Termination::Converged, "converged"},
    {Termination::MaxIterations, "max_iterations"}, {Termination::RankDeficient, "rank_deficient"},
    {Termination::Unstable, "unstable"},           {Termination::NumericalFailure, "numerical_failure"},
    {Termination::Interrupted, "interrupted"},     {Termination::Unidentifiable, "unidentifiable"},
    {Termination::AtBound, "at_bound"},
};
}  // namespace

const char* to_string(Termination t) {
  for (const auto& [k, name] : kNames)
    if (k == t) return name;
  CTID_ASSERT(false);
}

Termination termination_from_string(const std::string& name) {
  for (const auto& [k, n] : kNames)
    if (name == n) return k;
  throw InvalidArgument(detail::format("unknown termination '{}'", name));
}

}  // namespace ctid
