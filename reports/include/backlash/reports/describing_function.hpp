// backlash/reports/describing_function.hpp — the classical prediction of a backlash limit
// cycle, for comparison with the exact one: numeric's (backlash/numeric/describing_function.hpp,
// where a cold limit-cycle search also takes its first guess), named in backlash::reports.
#pragma once

#include "backlash/numeric/describing_function.hpp"

namespace backlash::reports {

using numeric::backlash_describing_function;
using numeric::describing_function_prediction;
using numeric::DescribingFunctionCycle;
using numeric::DescribingFunctionPrediction;

}  // namespace backlash::reports
