// ctid — the run functions of the registry's fits (src/estimate/fit.cpp), one per method that fits records;
// methods.cpp puts each into its registry entry. Private to the library.
#pragma once

#include "ctid/estimate/fit.hpp"

namespace ctid::fit_runs {

FitOutcome lssvf(const FitRequest& r);
FitOutcome ivsvf(const FitRequest& r);
FitOutcome rls_svf(const FitRequest& r);
FitOutcome srivc(const FitRequest& r);
FitOutcome srivc_auto(const FitRequest& r);
FitOutcome oe(const FitRequest& r);
FitOutcome tfest(const FitRequest& r);
FitOutcome fsf(const FitRequest& r);
FitOutcome physical(const FitRequest& r);
FitOutcome greybox(const FitRequest& r);
FitOutcome modal(const FitRequest& r);
FitOutcome narx(const FitRequest& r);
FitOutcome kia(const FitRequest& r);
FitOutcome subspace(const FitRequest& r);
FitOutcome ssest(const FitRequest& r);

}  // namespace ctid::fit_runs
