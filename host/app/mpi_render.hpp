// `candela render --mpi`: one render spread over the ranks of an MPI job (mpirun -np N).
// Rank r renders its own block of the sample indices (a shard, as with --sample-offset),
// rank 0 gathers the films and merges them by sample count (merge_films: mean and M2,
// so --variance stays exact) and writes the outputs. Built only with -DCANDELA_MPI=ON;
// otherwise every function here throws Error saying so.
#pragma once

#include <cstdint>

#include "render/film.hpp"

namespace candela {

bool mpi_built_in();

// MPI_Init on construction, MPI_Finalize on destruction
class MpiSession {
 public:
  MpiSession();
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  int rank() const { return rank_; }
  int size() const { return size_; }

 private:
  int rank_ = 0, size_ = 1;
};

// Rank `rank`'s block of [0, spp): the first spp % size ranks take one sample more.
// Sets *begin (offset from the render's first index) and *count (may be 0 when there
// are more ranks than samples).
void mpi_block(uint32_t spp, int rank, int size, uint32_t* begin, uint32_t* count);

// Rank 0 gets every rank's film merged in rank order; other ranks get their own back.
// *spp and *seconds become the sum of the ranks' spp and the longest rank's seconds;
// *interrupted and *partial become true if they are on any rank.
Film mpi_gather_films(const MpiSession& s, const Film& film, uint32_t* spp, double* seconds, bool* interrupted,
                      bool* partial);

// Ends the whole job after an error on one rank (the others may wait in a collective)
[[noreturn]] void mpi_abort(int code);

}  // namespace candela
