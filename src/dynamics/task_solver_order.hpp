// The solver's view of a Task: its constraints in solver order (last body
// first) and the maps between solver columns, balance rows and the user's
// rows (Task::Layout, src/model/task_layout.hpp). Not installed: a user
// sees the task's rows, not how the sweeps lay them out.
#pragma once

#include <vector>

#include "model/task_layout.hpp"
#include "zwang/task.hpp"

namespace zwang {

class TaskSolverOrder {
 public:
  using ConstraintGroup = Task::Layout::ConstraintGroup;

  explicit TaskSolverOrder(const Task& task) : layout_(*task.layout_) {}

  /// The constraints' pieces in solver order (Task::Layout::groups).
  const std::vector<ConstraintGroup>& groups() const { return layout_.groups; }
  /// The row of each solver column: a user row (< constraintRows()) or a mimic row.
  const std::vector<int>& solverRowToUserRow() const { return layout_.solver_row; }
  /// End of the solver columns acting on bodies b, b+1, … (a leading block
  /// [0, columnsEnd(b)): also their count).
  int columnsEnd(int body) const { return layout_.columns_end[static_cast<std::size_t>(body)]; }
  /// First solver column acting on body b's subtree; the block is [firstColumn(b), columnsEnd(b)).
  int firstColumn(int body) const { return layout_.first_column[static_cast<std::size_t>(body)]; }
  /// True when the balance works on rows, each the sum of its solver columns (balanceRowOfColumn).
  bool balanceOnRows() const { return layout_.balance_on_rows; }
  /// The balance row of each solver column (the identity without relative constraints).
  const std::vector<int>& balanceRowOfColumn() const { return layout_.balance_row; }
  /// Per solver column: 1 when its force is a contact's (the environment's), else 0.
  const std::vector<char>& contactColumns() const { return layout_.contact_column; }

 private:
  const Task::Layout& layout_;
};

// The view is a reference: made where it is read, it costs nothing once inlined.
inline TaskSolverOrder solverOrder(const Task& task) { return TaskSolverOrder(task); }

}  // namespace zwang
