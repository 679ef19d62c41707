// zwang: constrained hybrid dynamics (Popov–Vereshchagin) with static friction.
#pragma once

#include "zwang/hybrid_dynamics.hpp"
#include "zwang/inverse_dynamics.hpp"
#include "zwang/kinematics.hpp"
#include "zwang/model.hpp"
#include "zwang/status.hpp"
#include "zwang/task.hpp"
#include "zwang/urdf.hpp"
#include "zwang/workspace.hpp"
#include "zwang/friction.hpp"
