// Scheduling priority of the calling thread, for background stages that must not take CPU
// from the odometry when both want it.
#pragma once

namespace scfloam {

// Raises the calling thread's nice value by `increment` (Linux: nice is per thread; other
// threads keep theirs). Lowering priority needs no privilege. Returns false where it is not
// supported or the system refused; the thread then runs at its old priority.
bool lower_current_thread_priority(int increment);

// The calling thread's nice value (0 where unsupported).
int current_thread_nice();

}  // namespace scfloam
