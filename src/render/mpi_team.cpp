#include "render/mpi_team.h"

#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <thread>

#include "base/bytes.h"
#include "base/error.h"

namespace bpm {
namespace {

constexpr int kTagAsk = 1, kTagGive = 2, kTagFilm = 3;
// MPI counts are ints: large buffers go in pieces.
constexpr size_t kPiece = size_t(1) << 30;

class MpiTeam : public Team {
 public:
  MpiTeam() {
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
  }
  int rank() const override { return rank_; }
  int size() const override { return size_; }

  int share_passes(int begin, int end, const std::function<bool(int)>& run) override {
    if (rank_ != 0) {
      int done = 0, ok = 1;
      for (;;) {
        MPI_Send(&ok, 1, MPI_INT, 0, kTagAsk, MPI_COMM_WORLD);
        int p = -1;
        MPI_Recv(&p, 1, MPI_INT, 0, kTagGive, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        if (p < 0) return done;
        ok = run(p) ? 1 : 0;
        done += ok;
      }
    }
    // Process 0 renders its passes on this thread (always the same one, so that per-thread
    // storage does not grow) while a second thread hands out passes to the others; only one of
    // the two calls MPI meanwhile (MPI_THREAD_SERIALIZED).
    std::mutex m;
    int next = begin;
    bool stop = false;
    auto give = [&] {
      std::lock_guard<std::mutex> lock(m);
      return !stop && next < end ? next++ : -1;
    };
    auto halt = [&] {
      std::lock_guard<std::mutex> lock(m);
      stop = true;
    };
    std::thread server([&] {
      for (int waiting = size_ - 1; waiting > 0;) {
        int asked = 0;
        MPI_Status st;
        MPI_Iprobe(MPI_ANY_SOURCE, kTagAsk, MPI_COMM_WORLD, &asked, &st);
        if (!asked) {
          std::this_thread::sleep_for(std::chrono::microseconds(100));
          continue;
        }
        int ok = 1;
        MPI_Recv(&ok, 1, MPI_INT, st.MPI_SOURCE, kTagAsk, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        if (!ok) halt();
        int p = give();
        MPI_Send(&p, 1, MPI_INT, st.MPI_SOURCE, kTagGive, MPI_COMM_WORLD);
        if (p < 0) --waiting;
      }
    });
    int done = 0;
    try {
      for (int p; (p = give()) >= 0;) {
        if (run(p))
          ++done;
        else
          halt();
      }
    } catch (...) {
      halt();
      server.join();
      throw;
    }
    server.join();
    return done;
  }

  void gather_film(Film* film) override {
    if (rank_ != 0) {
      ByteWriter w;
      w.reserve(film->bytes() + 64);
      film->save(w);
      send_bytes(w.bytes(), 0);
      film->clear();
      return;
    }
    // In rank order, so that the sums do not depend on which process answers first.
    Film other(film->width(), film->height(), film->m_images(), film->sensor_count());
    other.set_spectral(film->spectral());
    for (int r = 1; r < size_; ++r) {
      const std::vector<uint8_t> bytes = recv_bytes(r);
      ByteReader reader(bytes, "the film of process " + std::to_string(r));
      other.load(reader);
      film->add(other);
    }
  }

  // Reduced into process 0 and sent from there, so that every process has the very same bits
  // (an all-reduce may add in another order in each process).
  void sum(std::vector<double>* v) override {
    for (size_t at = 0; at < v->size(); at += kPiece / sizeof(double)) {
      const int n = int(std::min(kPiece / sizeof(double), v->size() - at));
      MPI_Reduce(rank_ == 0 ? MPI_IN_PLACE : v->data() + at, v->data() + at, n, MPI_DOUBLE, MPI_SUM,
                 0, MPI_COMM_WORLD);
      MPI_Bcast(v->data() + at, n, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    }
  }

  void broadcast(std::vector<uint8_t>* bytes) override {
    uint64_t n = bytes->size();
    MPI_Bcast(&n, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
    bytes->resize(n);
    for (size_t at = 0; at < n; at += kPiece)
      MPI_Bcast(bytes->data() + at, int(std::min<size_t>(kPiece, n - at)), MPI_BYTE, 0,
                MPI_COMM_WORLD);
  }

  std::vector<std::vector<double>> gather(const std::vector<double>& mine) override {
    const int n = int(mine.size());
    std::vector<double> all(rank_ == 0 ? size_t(n) * size_t(size_) : 0);
    MPI_Gather(mine.data(), n, MPI_DOUBLE, all.data(), n, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    std::vector<std::vector<double>> rows;
    if (rank_ == 0)
      for (int r = 0; r < size_; ++r)
        rows.emplace_back(all.begin() + r * n, all.begin() + (r + 1) * n);
    return rows;
  }

 private:
  static void send_bytes(const std::vector<uint8_t>& bytes, int to) {
    uint64_t n = bytes.size();
    MPI_Send(&n, 1, MPI_UINT64_T, to, kTagFilm, MPI_COMM_WORLD);
    for (size_t at = 0; at < n; at += kPiece)
      MPI_Send(bytes.data() + at, int(std::min<size_t>(kPiece, n - at)), MPI_BYTE, to, kTagFilm,
               MPI_COMM_WORLD);
  }
  static std::vector<uint8_t> recv_bytes(int from) {
    uint64_t n = 0;
    MPI_Recv(&n, 1, MPI_UINT64_T, from, kTagFilm, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    std::vector<uint8_t> bytes(n);
    for (size_t at = 0; at < n; at += kPiece)
      MPI_Recv(bytes.data() + at, int(std::min<size_t>(kPiece, n - at)), MPI_BYTE, from, kTagFilm,
               MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    return bytes;
  }
  int rank_ = 0, size_ = 1;
};

// Whether a launcher started this process as part of a job (Open MPI, PMIx, PMI).
bool started_by_launcher() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE"})
    if (std::getenv(v)) return true;
  return false;
}

}  // namespace

MpiSession::MpiSession(int* argc, char*** argv) {
  if (!started_by_launcher()) return;
  // A process waiting for the others (for its next pass, at a round's end) yields its core
  // instead of spinning on it: with as many processes as cores, spinning took a third of the
  // rendering processes' time. A value the user set stays.
  setenv("OMPI_MCA_mpi_yield_when_idle", "1", 0);
  int provided = 0;
  MPI_Init_thread(argc, argv, MPI_THREAD_SERIALIZED, &provided);
  initialised_ = true;
  if (provided < MPI_THREAD_SERIALIZED) {
    std::fprintf(stderr,
                 "bpm: error: this MPI library cannot be called from two threads in turn "
                 "(MPI_THREAD_SERIALIZED), which distributed rendering needs\n");
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  int size = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (size > 1) team_ = std::make_unique<MpiTeam>();
}

MpiSession::~MpiSession() {
  if (initialised_) MPI_Finalize();
}

void MpiSession::abort(int code) {
  if (initialised_) MPI_Abort(MPI_COMM_WORLD, code);
  std::exit(code);
}

}  // namespace bpm
