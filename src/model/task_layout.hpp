// A Task's constraints as the solver reads them (Task::Layout, behind the
// Task's pointer): each constraint's pieces on the bodies its force acts on,
// sorted last body first, and the maps between solver columns, balance rows
// and the user's rows. Not installed: a user sees the task's rows; the
// solver sees them through src/dynamics/task_solver_order.hpp.
#pragma once

#include <vector>

#include "zwang/task.hpp"

namespace zwang {

struct Task::Layout {
  /// The constraints on one frame, as the solver reads them. A relative
  /// constraint appears twice: on the constrained frame's body, and (with
  /// `reference_side`) on the reference frame's body, where its force is −A ν.
  struct ConstraintGroup {
    int frame;                    ///< frame index (of the constrained frame, on both sides)
    int body;                     ///< the body this side's force acts on
    Expressed expressed;          ///< axes of A's columns
    int first_row;                ///< in the user's row order (b, ν)
    int rows;                     ///< number of rows (columns of A)
    ConstraintMatrix A;           ///< 6 × rows
    int reference = -1;           ///< the frame a relative constraint refers to (−1: the world)
    bool reference_side = false;  ///< this entry is the reference (or parent body's) side
    /// A piece of a joint row (rows = 1, A unused): coefficient·q̈_dof, for
    /// the DOF of this entry of v, read as a unit effort along it on the body
    /// it moves and its opposite on the parent body (reference_side). −1: a
    /// frame constraint.
    int dof = -1;
    double coefficient = 0.0;  ///< 1 for the joint of a joint row or a mimic joint, −multiplier for a leader
    bool mimic_row = false;    ///< a piece of a mimic row (its first_row counts the mimic rows)
    bool contact = false;      ///< the environment supplies its force (addContact)
  };

  /// Groups sorted by body, last body first ("solver order"): since the
  /// bodies are in depth-first order, the columns acting on a body's subtree
  /// are then a contiguous block [first_column[b], columns_end[b]), and for a
  /// chain the columns acting on bodies i..N a leading block.
  std::vector<ConstraintGroup> groups;
  std::vector<int> subtree_end;  // per body, copied from the model
  /// The row of each solver column: a user row (< constraintRows()) or a mimic row.
  std::vector<int> solver_row;
  /// The balance row of each solver column (the identity without relative constraints).
  std::vector<int> balance_row;
  /// Per body b, end of the solver columns acting on bodies b, b+1, … (also
  /// their count); one entry more, 0, for "beyond the last body".
  std::vector<int> columns_end;
  /// Per body b, the first solver column acting on b's subtree.
  std::vector<int> first_column;
  /// Per solver column: 1 when its force is a contact's (the environment's), else 0.
  std::vector<char> contact_column;
  /// True when some balance row has several solver columns (a relative
  /// constraint or a mimic joint): then the balance works on rows, each the
  /// sum of its solver columns.
  bool balance_on_rows = false;
};

}  // namespace zwang
