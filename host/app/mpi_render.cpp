// `candela render --mpi` (mpi_render.hpp): the MPI session, the sample blocks and the films' gathering.
#include "app/mpi_render.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "app/render_command.hpp"
#include "base/error.hpp"
#include "device/device.hpp"

#ifdef CANDELA_WITH_MPI
#include <mpi.h>
#endif

namespace candela {

void mpi_block(uint32_t spp, int rank, int size, uint32_t* begin, uint32_t* count) {
  uint32_t n = uint32_t(size), r = uint32_t(rank);
  uint32_t base = spp / n, extra = spp % n;
  *count = base + (r < extra ? 1 : 0);
  *begin = r * base + (r < extra ? r : extra);
}

#ifdef CANDELA_WITH_MPI

bool mpi_built_in() { return true; }

MpiSession::MpiSession() {
  int provided = 0;
  // Render threads never call MPI: only the main thread does
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
}

MpiSession::~MpiSession() { MPI_Finalize(); }

Film mpi_gather_films(const MpiSession& s, const Film& film, uint32_t* spp, double* seconds, bool* interrupted,
                      bool* partial) {
  const int n = int(film.mean.size());
  const int parts = film.aov.empty() ? 2 : 4;  // mean, m2 and the AOVs' two (every rank alike)
  std::vector<float> mine(parts * size_t(n));
  std::copy(film.mean.begin(), film.mean.end(), mine.begin());
  std::copy(film.m2.begin(), film.m2.end(), mine.begin() + n);
  std::copy(film.aov.begin(), film.aov.end(), mine.begin() + 2 * size_t(n));
  std::vector<float> all(s.rank() == 0 ? mine.size() * size_t(s.size()) : 0);
  MPI_Gather(mine.data(), parts * n, MPI_FLOAT, all.data(), parts * n, MPI_FLOAT, 0, MPI_COMM_WORLD);
  unsigned long long my_spp = *spp, total_spp = 0;
  MPI_Reduce(&my_spp, &total_spp, 1, MPI_UNSIGNED_LONG_LONG, MPI_SUM, 0, MPI_COMM_WORLD);
  double longest = 0.0;
  MPI_Reduce(seconds, &longest, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
  int flags[2] = {*interrupted ? 1 : 0, *partial ? 1 : 0}, any[2] = {0, 0};
  MPI_Reduce(flags, any, 2, MPI_INT, MPI_LOR, 0, MPI_COMM_WORLD);
  if (s.rank() != 0) return film;
  *spp = uint32_t(total_spp);
  *seconds = longest;
  *interrupted = any[0];
  *partial = any[1];
  Film out;
  for (int r = 0; r < s.size(); ++r) {
    Film f(film.width, film.height);
    const float* src = all.data() + size_t(r) * parts * n;
    std::copy(src, src + n, f.mean.begin());
    std::copy(src + n, src + 2 * n, f.m2.begin());
    if (parts == 4) f.aov.assign(src + 2 * n, src + 4 * size_t(n));
    out = r == 0 ? std::move(f) : merge_films(out, f);
  }
  return out;
}

// Each rank's (position or -1, exposure or NaN); the earliest position's exposure wins
static std::optional<float> mpi_gather_exposure(std::optional<size_t> position, std::optional<float> mine) {
  double own[2] = {position ? double(*position) : -1.0, mine ? double(*mine) : std::nan("")};
  int size = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  std::vector<double> all(2 * size_t(size));
  MPI_Allgather(own, 2, MPI_DOUBLE, all.data(), 2, MPI_DOUBLE, MPI_COMM_WORLD);
  double best = -1.0;
  std::optional<float> chosen;
  for (int r = 0; r < size; ++r) {
    double at = all[2 * size_t(r)];
    if (at < 0.0 || (best >= 0.0 && at >= best)) continue;
    best = at;
    chosen = std::isnan(all[2 * size_t(r) + 1]) ? std::nullopt : std::optional<float>(float(all[2 * size_t(r) + 1]));
  }
  return chosen;
}

void mpi_abort(int code) {
  MPI_Abort(MPI_COMM_WORLD, code);
  std::_Exit(code);
}

#else

namespace {
[[noreturn]] void no_mpi() {
  throw Error("--mpi: this candela was built without MPI (configure with -DCANDELA_MPI=ON)");
}
}  // namespace

bool mpi_built_in() { return false; }
MpiSession::MpiSession() { no_mpi(); }
MpiSession::~MpiSession() = default;
Film mpi_gather_films(const MpiSession&, const Film&, uint32_t*, double*, bool*, bool*) { no_mpi(); }
void mpi_abort(int code) { std::_Exit(code); }
static std::optional<float> mpi_gather_exposure(std::optional<size_t>, std::optional<float> mine) { return mine; }

#endif

namespace {
MpiSession* g_mpi = nullptr;  // the job's session while a render runs under it
bool g_by_frames = false;     // a sequence under it: each rank renders whole frames
}  // namespace

int run_render_under_mpi(const RenderArgs& a, int (*run)(RenderArgs)) {
  MpiSession session;
  g_mpi = &session;
  try {
    int rc = run(a);
    g_mpi = nullptr;
    return rc;
  } catch (const cl::Error& e) {
    std::fprintf(stderr, "candela: error: rank %d: %s\n", session.rank(), cl_error_message(e.what(), e.err()).c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "candela: error: rank %d: %s\n", session.rank(), e.what());
  }
  std::fflush(stderr);
  if (session.size() > 1) mpi_abort(1);
  g_mpi = nullptr;
  return 1;
}

int mpi_ranks() { return g_mpi ? g_mpi->size() : 0; }

void mpi_split_by_frames() { g_by_frames = g_mpi != nullptr; }

bool mpi_renders_frame(size_t index) {
  return !g_mpi || index % size_t(g_mpi->size()) == size_t(g_mpi->rank());
}

std::optional<float> mpi_sequence_exposure(std::optional<size_t> position, std::optional<float> mine) {
  return g_mpi ? mpi_gather_exposure(position, mine) : mine;
}

uint32_t mpi_shard(RenderArgs* a, uint32_t* spp) {
  if (!g_mpi || g_by_frames) return a->sample_offset;
  if (*spp == 0) throw Error("--mpi needs --spp: each rank renders a fixed block of the sample indices");
  if (*spp < uint32_t(g_mpi->size()))
    throw Error("--mpi: --spp " + std::to_string(*spp) + " is fewer than the " + std::to_string(g_mpi->size()) +
                " ranks");
  uint32_t begin = 0, count = 0;
  mpi_block(*spp, g_mpi->rank(), g_mpi->size(), &begin, &count);
  if (g_mpi->rank() != 0) a->quiet = true;
  *spp = count;
  return a->sample_offset + begin;
}

bool mpi_combine(RenderResult* r) {
  if (!g_mpi || g_by_frames) return true;
  r->film = mpi_gather_films(*g_mpi, r->film, &r->spp, &r->seconds, &r->interrupted, &r->partial_pass);
  return g_mpi->rank() == 0;
}

}  // namespace candela
