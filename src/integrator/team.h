// Several processes rendering one image (`mpirun -n K bpm render ...`; render/mpi_team.h is the
// Open MPI implementation). run_passes shares each round's passes among them: a pass goes to
// whichever process asks first, so a slow process takes fewer and holds nobody back. At the end
// of a round the films' sums meet in process 0, what the integrators learnt is added up in every
// process, and process 0's decisions (the next round's sampling probabilities, whether to go on)
// reach every process. Process 0 alone writes outputs and prints progress.
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

#include "film/film.h"

namespace bpm {

class Team {
 public:
  virtual ~Team() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  // This process's share of passes [begin, end): run(p) for every pass it is given, until the
  // passes are all given out or a run returns false (the pass was cut: the render stops, and no
  // process is given another). Returns the passes this process completed.
  virtual int share_passes(int begin, int end, const std::function<bool(int)>& run) = 0;
  // Adds every process's film into process 0's; the others' are cleared.
  virtual void gather_film(Film* film) = 0;
  // Adds the vector over every process (the same length everywhere), in place, everywhere.
  virtual void sum(std::vector<double>* v) = 0;
  // Process 0's bytes, to every process.
  virtual void broadcast(std::vector<uint8_t>* bytes) = 0;
  // Every process's values, in process 0 (one row per process, in rank order; empty elsewhere).
  virtual std::vector<std::vector<double>> gather(const std::vector<double>& mine) = 0;
};

}  // namespace bpm
