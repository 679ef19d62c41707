/// \file
/// zwang: constrained hybrid dynamics (Popov–Vereshchagin) with static friction.
#pragma once

#include "zwang/center_of_mass.hpp"
#include "zwang/configuration.hpp"
#include "zwang/friction.hpp"
#include "zwang/hybrid_dynamics.hpp"
#include "zwang/inverse_dynamics.hpp"
#include "zwang/kinematics.hpp"
#include "zwang/model.hpp"
#include "zwang/orientation.hpp"
#include "zwang/placement.hpp"
#include "zwang/simulation.hpp"
#include "zwang/status.hpp"
#include "zwang/task.hpp"
#include "zwang/urdf.hpp"
#include "zwang/version.hpp"
#include "zwang/workspace.hpp"

/// \namespace zwang
/// Constrained hybrid dynamics (Popov–Vereshchagin) with static friction: Model,
/// Task and Workspace, the solvers and the classic algorithms. The conventions
/// (frames, linear-first spatial vectors, signs) are those of docs/conventions.md.
