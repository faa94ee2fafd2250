// MpiTwinPool's speed-up for a twin that waits, the MPI counterpart of ExternalTwinPool's
// benchmark (benchmarks/external): tests/data/script_twin.py sleeping 50 ms per control, one
// batch of 231 controls (the paper's w-controller at d = 3: 33 candidates × 7 sigma points)
// spread over the job's worker ranks (every rank but 0, one twin process each). Run it under
// mpiexec with 2 … 17 ranks; it prints one Markdown row:
//   | worker ranks | wall time per batch | speed-up | ideal 231 / ⌈231/N⌉ | speed-up ÷ N |
// after a warm-up batch that starts the processes. Not a Google Benchmark program: its
// processes are MPI ranks.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <fmt/format.h>

#include "twincal/core/stopwatch.hpp"
#include "twincal/distributed/mpi_environment.hpp"
#include "twincal/distributed/mpi_twin_pool.hpp"
#include "twincal/distributed/mpi_twin_service.hpp"

namespace {

constexpr twincal::Index kBatch = 231;
constexpr double kSecondsPerControl = 0.05;
constexpr int kBatches = 2;

void measure(twincal::MpiTwinService& service) {
  twincal::ExternalTwinSettings settings;
  settings.command = {TWINCAL_TEST_DATA_DIR "/script_twin.py"};
  settings.locators = {"A", "B", "C"};
  settings.lower_bounds = {-1.0, -1.0, -1.0};
  settings.upper_bounds = {1.0, 1.0, 1.0};
  settings.upper_parts = 1;
  settings.lower_parts = 1;
  settings.timeout_ms = 60'000;
  const twincal::MpiTwinPool pool(service, settings);
  const nlohmann::json assembly = {
      {"q0", 0.25}, {"a", {0.1, -0.2, 0.0}}, {"sleep", kSecondsPerControl}};
  const twincal::MatrixX controls = twincal::MatrixX::Random(3, kBatch) * 0.1;
  twincal::VectorX out(kBatch);
  const twincal::Index n = pool.workers();
  pool.quality_batch(assembly, controls.leftCols(n), out.head(n));  // one control per rank
  const twincal::Stopwatch watch;
  for (int b = 0; b < kBatches; ++b) pool.quality_batch(assembly, controls, out);
  const double per_batch = watch.seconds() / kBatches;
  const double speedup = static_cast<double>(kBatch) * kSecondsPerControl / per_batch;
  const double ideal = static_cast<double>(kBatch) / static_cast<double>((kBatch + n - 1) / n);
  fmt::print("| {} | {:.0f} ms | {:.2f}× | {:.2f}× | {:.3f} |\n", n, per_batch * 1e3, speedup,
             ideal, speedup / static_cast<double>(n));
}

}  // namespace

int main() {
  try {
    const twincal::MpiEnvironment mpi;
    if (mpi.rank() != 0) {
      twincal::serve_twin_requests(mpi);
      return 0;
    }
    twincal::MpiTwinService service(mpi);
    service.run([&] { measure(service); });
    return 0;
  } catch (const std::exception& error) {
    fmt::print(stderr, "twincal_mpi_twin_pool_benchmark: {}\n", error.what());
    return 1;
  }
}
