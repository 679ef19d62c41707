// Small models the simulation tests share (test_simulation, test_no_allocation).
#pragma once

#include "zwang/model.hpp"

namespace zwang::testing {

// A 1 kg pendulum (centre of mass 0.5 m below a hinge about y) with limits at ±0.5 rad and 0.05 N·m of breakaway and
// kinetic friction: from q = 0.2 rad at 3 rad/s it reaches its upper limit.
Model limitPendulum();

}  // namespace zwang::testing
