// The processes of an Open MPI job as a Team (integrator/team.h). Built only where MPI is found
// (BPM_HAVE_MPI). MpiSession initialises MPI for the program's lifetime when it runs under
// mpirun. While passes are shared out, process 0 renders on its main thread and a second thread
// hands out passes; the two never call MPI at once (MPI_THREAD_SERIALIZED).
#pragma once
#include <memory>

#include "integrator/team.h"

namespace bpm {

class MpiSession {
 public:
  // Initialises MPI when the program was started by mpirun (or with more than one process).
  MpiSession(int* argc, char*** argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  // The job's processes; null outside mpirun.
  Team* team() { return team_.get(); }
  // Ends every process of the job at once (an error in one of them would leave the others
  // waiting for it forever).
  [[noreturn]] void abort(int code);

 private:
  bool initialised_ = false;
  std::unique_ptr<Team> team_;
};

}  // namespace bpm
