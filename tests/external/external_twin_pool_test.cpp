#include "twincal/external/external_twin_pool.hpp"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <set>
#include <string>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace twincal {
namespace {

using ::testing::HasSubstr;
using json = nlohmann::json;

// tests/data/script_twin.py: Q = sqrt(q0 + Σ (u_i − a_i)²), misbehaving on request.
ExternalTwinPoolOptions pool_options(Index workers) {
  ExternalTwinPoolOptions options;
  options.twin.command = {TWINCAL_TEST_DATA_DIR "/script_twin.py"};
  options.twin.locator_names = {"A", "B"};
  // Generous: these bound only failures, and the machine may be loaded or sanitized.
  options.twin.timeout = std::chrono::milliseconds{5000};
  options.twin.startup_grace = std::chrono::milliseconds{10000};
  options.workers = workers;
  return options;
}

const json kPoolAssembly = {{"q0", 0.25}, {"a", {0.1, -0.2}}};

json pool_assembly(const std::string& mode) {
  json assembly = kPoolAssembly;
  assembly["mode"] = mode;
  return assembly;
}

// A marker file that makes "crash_once" / "hang_once" misbehave in exactly one process.
class Marker {
 public:
  Marker()
      : path_(std::filesystem::temp_directory_path() /
              fmt::format("twincal-pool-{}-{}", ::getpid(), next_++)) {
    std::filesystem::remove(path_);
  }
  Marker(const Marker&) = delete;
  Marker& operator=(const Marker&) = delete;
  ~Marker() { std::filesystem::remove(path_); }
  [[nodiscard]] json assembly(const std::string& mode) const {
    json out = pool_assembly(mode);
    out["marker"] = path_.string();
    return out;
  }

 private:
  static inline int next_ = 0;
  std::filesystem::path path_;
};

MatrixX pool_controls(Index k) {
  MatrixX controls(2, k);
  for (Index j = 0; j < k; ++j) {
    controls(0, j) = 0.1 * static_cast<double>(j) - 0.3;
    controls(1, j) = 0.05 * static_cast<double>(j * j % 7);
  }
  return controls;
}

VectorX pool_expected(const MatrixX& controls) {
  VectorX out(controls.cols());
  for (Index j = 0; j < controls.cols(); ++j) {
    out(j) =
        std::sqrt(0.25 + std::pow(controls(0, j) - 0.1, 2) + std::pow(controls(1, j) + 0.2, 2));
  }
  return out;
}

TEST(ExternalTwinPool, GivesTheSameQualitiesForAnyNumberOfWorkers) {
  const MatrixX controls = pool_controls(7);
  VectorX single(7);
  ExternalTwinPool(pool_options(1)).quality_batch(kPoolAssembly, controls, single);
  EXPECT_TRUE(single.isApprox(pool_expected(controls), 1e-15));
  for (const Index workers : {2, 3, 5, 9}) {
    const ExternalTwinPool pool(pool_options(workers));
    EXPECT_EQ(pool.workers(), workers);
    EXPECT_EQ(pool.starts(), workers);
    VectorX out(7);
    pool.quality_batch(kPoolAssembly, controls, out);
    EXPECT_EQ(out, single) << workers << " workers";
  }
}

// Deviations are spread like qualities: the same m × k block for any number of workers.
TEST(ExternalTwinPool, GivesTheSameDeviationsForAnyNumberOfWorkers) {
  const MatrixX controls = pool_controls(7);
  ExternalTwinPoolOptions options = pool_options(1);
  options.twin.key_points = 3;
  MatrixX single(3, 7);
  ExternalTwinPool(options).deviations_batch(kPoolAssembly, controls, single);
  EXPECT_TRUE((single.colwise().norm().transpose() / std::sqrt(3.0))
                  .isApprox(pool_expected(controls), 1e-15));
  for (const Index workers : {3, 9}) {
    options.workers = workers;
    const ExternalTwinPool pool(options);
    EXPECT_EQ(pool.key_point_count(), 3);
    MatrixX out(3, 7);
    pool.deviations_batch(kPoolAssembly, controls, out);
    EXPECT_EQ(out, single) << workers << " workers";
    pool.worker_deviations_batch(1, kPoolAssembly, controls, out);
    EXPECT_EQ(out, single) << workers << " workers, on worker 1";
  }
  MatrixX deviations(3, 2);
  EXPECT_THROW(ExternalTwinPool(pool_options(2))
                   .deviations_batch(kPoolAssembly, pool_controls(2), deviations),
               InvalidArgumentError);
}

TEST(ExternalTwinPool, CutsABatchIntoContiguousChunksOneWorkerEach) {
  const ExternalTwinPool pool(pool_options(3));
  VectorX pids(7);
  pool.quality_batch(pool_assembly("pid"), pool_controls(7), pids);
  // Chunks [0, 2), [2, 4), [4, 7): one process each.
  EXPECT_EQ(pids(0), pids(1));
  EXPECT_EQ(pids(2), pids(3));
  EXPECT_EQ(pids(4), pids(6));
  EXPECT_EQ(std::set<double>(pids.begin(), pids.end()).size(), 3U);
  VectorX two(2);  // fewer controls than workers: one control per worker
  pool.quality_batch(pool_assembly("pid"), pool_controls(2), two);
  EXPECT_NE(two(0), two(1));
  EXPECT_EQ(pool.quality(kPoolAssembly, pool_controls(1).col(0)),
            pool_expected(pool_controls(1))(0));
}

TEST(ExternalTwinPool, RetriesTheChunkOfACrashedOrHungWorkerOnceOnARestartedWorker) {
  for (const std::string mode : {"crash_once", "hang_once"}) {
    ExternalTwinPoolOptions options = pool_options(3);
    options.twin.timeout = std::chrono::milliseconds{400};  // the hang's; a reply takes ~1 ms
    const ExternalTwinPool pool(options);
    const Marker marker;
    const MatrixX controls = pool_controls(6);
    VectorX out(6);
    // Every worker answers once first: until then a worker's deadline includes startup_grace.
    pool.quality_batch(kPoolAssembly, controls, out);
    pool.quality_batch(marker.assembly(mode), controls, out);
    EXPECT_TRUE(out.isApprox(pool_expected(controls), 1e-15)) << mode;
    EXPECT_EQ(pool.retries(), 1U) << mode;
    EXPECT_EQ(pool.starts(), 4) << mode;  // the misbehaving worker was restarted
  }
}

TEST(ExternalTwinPool, ReportsAChunkThatFailsAgainAsTypedNamingTheWorker) {
  for (const auto& [mode, failure] : {std::pair{"crash", ExternalTwinFailure::crashed},
                                      std::pair{"garbage", ExternalTwinFailure::malformed_reply},
                                      std::pair{"wrong_count", ExternalTwinFailure::wrong_count}}) {
    const ExternalTwinPool pool(pool_options(2));
    VectorX out(4);
    try {
      pool.quality_batch(pool_assembly(mode), pool_controls(4), out);
      ADD_FAILURE() << mode << ": expected an ExternalTwinError";
    } catch (const ExternalTwinError& error) {
      EXPECT_EQ(error.failure(), failure) << mode;
      EXPECT_THAT(error.what(), HasSubstr("worker 0 of 2, controls 0…1, on the retry"));
      EXPECT_EQ(error.controls().cols(), 2) << mode;  // the chunk's
    }
    EXPECT_EQ(pool.retries(), 2U) << mode;                     // each chunk, once
    pool.quality_batch(kPoolAssembly, pool_controls(4), out);  // and the pool serves on
    EXPECT_TRUE(out.isApprox(pool_expected(pool_controls(4)), 1e-15)) << mode;
  }
}

TEST(ExternalTwinPool, DoesNotRetryWhatARetryCannotMend) {
  const ExternalTwinPool pool(pool_options(2));
  VectorX out(4);
  try {
    pool.quality_batch(pool_assembly("error"), pool_controls(4), out);
    ADD_FAILURE() << "expected an ExternalTwinError";
  } catch (const ExternalTwinError& error) {
    EXPECT_EQ(error.failure(), ExternalTwinFailure::twin_error);
    EXPECT_THAT(error.what(), HasSubstr("assembly rejected on purpose (worker 0 of 2"));
  }
  EXPECT_EQ(pool.retries(), 0U);
  EXPECT_EQ(pool.starts(), 2);

  ExternalTwinPoolOptions options = pool_options(2);
  options.retry = false;
  const ExternalTwinPool strict(options);
  EXPECT_THROW(strict.quality_batch(pool_assembly("crash"), pool_controls(4), out),
               ExternalTwinError);
  EXPECT_EQ(strict.retries(), 0U);
}

TEST(ExternalTwinPool, RejectsBadOptionsAndControlsBeforeStartingOrSending) {
  for (const Index workers : {Index{0}, Index{257}}) {
    try {
      const ExternalTwinPool pool(pool_options(workers));
      ADD_FAILURE() << "expected an InvalidArgumentError";
    } catch (const InvalidArgumentError& error) {
      EXPECT_THAT(error.what(), HasSubstr(fmt::format("workers: value is {}; rule", workers)));
    }
  }
  ExternalTwinPoolOptions no_command = pool_options(2);
  no_command.twin.command.clear();
  EXPECT_THROW(ExternalTwinPool{no_command}, InvalidArgumentError);

  const ExternalTwinPool pool(pool_options(2));
  MatrixX controls = pool_controls(3);
  controls(1, 2) = std::nan("");
  VectorX out(3);
  EXPECT_THROW(pool.quality_batch(kPoolAssembly, controls, out), NonFiniteError);
  EXPECT_THROW(pool.quality_batch(kPoolAssembly, MatrixX::Zero(3, 2), out), DimensionMismatchError);
  EXPECT_EQ(pool.starts(), 2);
}

TEST(ExternalTwinPool, ServesConcurrentBatches) {
  const ExternalTwinPool pool(pool_options(3));
  const MatrixX controls = pool_controls(8);
  VectorX first(8);
  VectorX second(8);
  {
    std::jthread other([&] { pool.quality_batch(kPoolAssembly, controls, first); });
    pool.quality_batch(kPoolAssembly, controls, second);
  }
  EXPECT_EQ(first, second);
  EXPECT_TRUE(first.isApprox(pool_expected(controls), 1e-15));
}

}  // namespace
}  // namespace twincal
