// `candela render --mpi`: one render spread over the ranks of an MPI job (mpirun -np N).
// Rank r renders its own block of the sample indices (a shard, as with --sample-offset),
// rank 0 gathers the films and merges them by sample count (merge_films: mean and M2,
// so --variance stays exact) and writes the outputs. Built only with -DCANDELA_MPI=ON;
// otherwise every function here throws Error saying so.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>

#include "render/film.hpp"
#include "render/renderer.hpp"

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

struct RenderArgs;

// `render --mpi`: `run` inside the job's session; an error on one rank ends the job (the
// others would wait for its film for ever)
int run_render_under_mpi(const RenderArgs& args, int (*run)(RenderArgs));

// The ranks of the job a render runs under (run_render_under_mpi), else 0
int mpi_ranks();

// A sequence under --mpi: the ranks split it by frames, each rendering and writing whole
// frames (mpi_shard and mpi_combine then leave the samples alone)
void mpi_split_by_frames();
// Whether this rank renders the sequence's index-th frame (every frame without --mpi)
bool mpi_renders_frame(size_t index);
// A sequence under --mpi: every rank calls this once, after metering its first frame (at
// `position` in the sequence; nullopt for a rank without frames), and all get the exposure
// of the earliest of those frames, so that no rank's frames flicker against another's.
// Without --mpi: `mine`.
std::optional<float> mpi_sequence_exposure(std::optional<size_t> position, std::optional<float> mine);
// This rank's first sample index, and in *spp its sample count: its block of the render's
// under --mpi (other ranks than 0 then render quietly), else --sample-offset and *spp as is
uint32_t mpi_shard(RenderArgs* args, uint32_t* spp);

// Under --mpi, rank 0 gets every rank's samples merged into its result; returns whether
// this rank writes the outputs (rank 0 only; every rank without --mpi)
bool mpi_combine(RenderResult* result);

}  // namespace candela
