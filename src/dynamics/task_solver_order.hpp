// The solver's view of a Task: its constraints in solver order (last body
// first) and the maps between solver columns, balance rows and the user's
// rows (Task's private accessors, documented there). Not installed: a user
// sees the task's rows, not how the sweeps lay them out.
#pragma once

#include <vector>

#include "zwang/task.hpp"

namespace zwang {

class TaskSolverOrder {
 public:
  using ConstraintGroup = zwang::Task::ConstraintGroup;

  explicit TaskSolverOrder(const Task& task) : task_(task) {}

  const std::vector<ConstraintGroup>& groups() const { return task_.groups(); }
  const std::vector<int>& solverRowToUserRow() const { return task_.solverRowToUserRow(); }
  int columnsEnd(int body) const { return task_.columnsEnd(body); }
  int firstColumn(int body) const { return task_.firstColumn(body); }
  bool balanceOnRows() const { return task_.balanceOnRows(); }
  const std::vector<int>& balanceRowOfColumn() const { return task_.balanceRowOfColumn(); }
  const std::vector<char>& contactColumns() const { return task_.contactColumns(); }

 private:
  const Task& task_;
};

// The view is a reference: made where it is read, it costs nothing once inlined.
inline TaskSolverOrder solverOrder(const Task& task) { return TaskSolverOrder(task); }

}  // namespace zwang
