// What the MJCF loader (mjcf.cpp) and the MuJoCo comparison (compare_mujoco.cpp) read off a compiled mjModel
// alike: one definition, so that both decide the same way.
#pragma once

#include <mujoco/mujoco.h>

namespace zwang::internal {

// The floating base: the world's only child body when it hangs on a free joint (its body index), else −1.
inline int floatingBaseBody(const mjModel* m) {
  int children = 0, body = -1;
  for (int b = 1; b < m->nbody; ++b)
    if (m->body_parentid[b] == 0) {
      ++children;
      body = b;
    }
  if (children != 1 || m->body_jntnum[body] < 1 || m->jnt_type[m->body_jntadr[body]] != mjJNT_FREE) return -1;
  return body;
}

}  // namespace zwang::internal
