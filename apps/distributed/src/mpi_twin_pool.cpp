#include "twincal/distributed/mpi_twin_pool.hpp"

#include <algorithm>
#include <exception>
#include <optional>
#include <utility>

#include <fmt/format.h>

#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/external/external_twin.hpp"
#include "twincal/models/twin.hpp"

namespace twincal {

using nlohmann::json;

MpiTwinPool::MpiTwinPool(MpiTwinService& service, const ExternalTwinSettings& settings)
    : service_(&service), twin_id_(service.next_twin_id()), key_points_(settings.key_points) {
  require_valid("external_twin", settings);
  locator_names_ = settings.locators;
  lower_bounds_ =
      Eigen::Map<const VectorX>(settings.lower_bounds.data(), std::ssize(settings.lower_bounds));
  upper_bounds_ =
      Eigen::Map<const VectorX>(settings.upper_bounds.data(), std::ssize(settings.upper_bounds));
  const json message{{"twin", twin_id_}, {"settings", settings}};
  std::vector<std::future<json>> replies;
  for (int rank = 1; rank <= static_cast<int>(workers()); ++rank) {
    replies.push_back(service.request(rank, MpiTwinService::start_tag, message));
  }
  std::optional<std::pair<int, json>> first_failure;
  for (std::size_t r = 0; r < replies.size(); ++r) {
    json reply = replies[r].get();
    if (!reply.contains("started") && !first_failure) {
      first_failure.emplace(static_cast<int>(r) + 1, std::move(reply));
    }
  }
  if (first_failure) {
    const auto& [rank, reply] = *first_failure;
    throw ExternalTwinError(
        ExternalTwinFailure::start_failed, "(none: starting the twin)", MatrixX(0, 0),
        fmt::format("rank {}: {}", rank,
                    reply.value("detail", reply.value("error", std::string("no reason given")))));
  }
}

std::future<json> MpiTwinPool::send_chunk(int rank, const json& assembly,
                                          const Eigen::Ref<const MatrixX>& controls, Index begin,
                                          Index count, bool deviations) const {
  std::vector<double> values;
  values.reserve(static_cast<std::size_t>(controls.rows() * count));
  for (Index j = begin; j < begin + count; ++j) {
    for (Index i = 0; i < controls.rows(); ++i) values.push_back(controls(i, j));
  }
  json message{{"twin", twin_id_},
               {"assembly", assembly},
               {"rows", controls.rows()},
               {"cols", count},
               {"controls", std::move(values)}};
  if (deviations) message["deviations"] = true;
  return service_->request(rank, MpiTwinService::evaluate_tag, std::move(message));
}

void MpiTwinPool::take_reply(const json& reply, int rank, const json& assembly,
                             const Eigen::Ref<const MatrixX>& controls,
                             Eigen::Ref<MatrixX> out) const {
  if (reply.contains("failure")) {
    throw ExternalTwinError(
        static_cast<ExternalTwinFailure>(reply.at("failure").get<int>()), assembly.dump(), controls,
        fmt::format("rank {}: {}", rank, reply.at("detail").get<std::string>()));
  }
  if (reply.contains("error")) {
    throw Error("twin",
                fmt::format("twin: rank {}: {}", rank, reply.at("error").get<std::string>()));
  }
  const std::vector<double> values = reply.at("values").get<std::vector<double>>();
  if (std::ssize(values) != out.size()) {
    throw Error("twin", fmt::format("twin: rank {} answered {} values for {} controls × {}", rank,
                                    values.size(), out.cols(), out.rows()));
  }
  out = Eigen::Map<const MatrixX>(values.data(), out.rows(), out.cols());
}

void MpiTwinPool::spread(const json& assembly, const Eigen::Ref<const MatrixX>& controls,
                         bool deviations, Eigen::Ref<MatrixX> out) const {
  require_finite("controls", controls);
  const Index k = controls.cols();
  if (k == 0) return;
  const Index chunks = std::min(workers(), k);
  std::vector<Index> begins;
  std::vector<std::future<json>> replies;
  for (Index i = 0, begin = 0; i < chunks; ++i) {
    const Index count = k / chunks + (i < k % chunks ? 1 : 0);
    begins.push_back(begin);
    replies.push_back(
        send_chunk(static_cast<int>(i) + 1, assembly, controls, begin, count, deviations));
    begin += count;
  }
  begins.push_back(k);
  std::exception_ptr first_failure;  // the lowest chunk's, whatever the timing
  for (Index i = 0; i < chunks; ++i) {
    const auto c = static_cast<std::size_t>(i);
    const Index count = begins[c + 1] - begins[c];
    try {
      take_reply(replies[c].get(), static_cast<int>(i) + 1, assembly,
                 controls.middleCols(begins[c], count), out.middleCols(begins[c], count));
    } catch (...) {
      if (!first_failure) first_failure = std::current_exception();
    }
  }
  if (first_failure) std::rethrow_exception(first_failure);
}

void MpiTwinPool::ask_worker(Index worker, const json& assembly,
                             const Eigen::Ref<const MatrixX>& controls, bool deviations,
                             Eigen::Ref<MatrixX> out) const {
  if (worker < 0 || worker >= workers()) {
    throw InvalidArgumentError(
        "worker", fmt::format("worker: is {}; rule: must lie in [0, {})", worker, workers()));
  }
  require_finite("controls", controls);
  if (controls.cols() == 0) return;
  const int rank = static_cast<int>(worker) + 1;
  take_reply(send_chunk(rank, assembly, controls, 0, controls.cols(), deviations).get(), rank,
             assembly, controls, out);
}

void MpiTwinPool::quality_batch(const json& assembly, const Eigen::Ref<const MatrixX>& controls,
                                Eigen::Ref<VectorX> out) const {
  require_control_batch(controls, out, control_dimension());
  spread(assembly, controls, /*deviations=*/false, Eigen::Map<MatrixX>(out.data(), 1, out.size()));
}

void MpiTwinPool::worker_quality_batch(Index worker, const json& assembly,
                                       const Eigen::Ref<const MatrixX>& controls,
                                       Eigen::Ref<VectorX> out) const {
  require_control_batch(controls, out, control_dimension());
  ask_worker(worker, assembly, controls, /*deviations=*/false,
             Eigen::Map<MatrixX>(out.data(), 1, out.size()));
}

void MpiTwinPool::deviations_batch(const json& assembly, const Eigen::Ref<const MatrixX>& controls,
                                   Eigen::Ref<MatrixX> out) const {
  require_key_points(key_points_);
  require_deviations_batch(controls, out, control_dimension(), key_points_);
  spread(assembly, controls, /*deviations=*/true, out);
}

void MpiTwinPool::worker_deviations_batch(Index worker, const json& assembly,
                                          const Eigen::Ref<const MatrixX>& controls,
                                          Eigen::Ref<MatrixX> out) const {
  require_key_points(key_points_);
  require_deviations_batch(controls, out, control_dimension(), key_points_);
  ask_worker(worker, assembly, controls, /*deviations=*/true, out);
}

}  // namespace twincal
