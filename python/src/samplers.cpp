// Sobol and Halton with scipy.stats.qmc's vocabulary: Sobol(d, scramble=..., seed=...),
// random(n) and random_base2(m) returning an n × d array, reset(), fast_forward(n). The points
// are written straight into the NumPy array: its row-major n × d memory is the samplers'
// column-major d × n batch.
#include <cstdint>
#include <optional>
#include <string>
#include <variant>

#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "twincal/core/error.hpp"
#include "twincal/samplers/balance_check.hpp"
#include "twincal/samplers/halton.hpp"
#include "twincal/samplers/sobol.hpp"

namespace py = pybind11;

namespace twincal::python {
namespace {

// The sampler's next n points as a new n × d array.
template <typename Sampler>
py::array_t<double> draw(Sampler& sampler, Index n) {
  if (n < 0) {
    throw InvalidArgumentError("n", fmt::format("n: value is {}; rule: must be >= 0", n));
  }
  py::array_t<double> points({n, sampler.dimension()});
  sampler.fill(Eigen::Map<MatrixX>(points.mutable_data(), sampler.dimension(), n));
  return points;
}

// SciPy's balance warning: a UserWarning (an error under `-W error`, which then propagates).
void warn(const std::string& message) {
  if (PyErr_WarnEx(PyExc_UserWarning, message.c_str(), 1) != 0) throw py::error_already_set();
}

SobolRandomization parse_scramble(const py::object& scramble) {
  if (py::isinstance<py::bool_>(scramble)) {
    return scramble.cast<bool>() ? SobolRandomization::linear_matrix_scramble
                                 : SobolRandomization::none;
  }
  if (py::isinstance<py::str>(scramble) && scramble.cast<std::string>() == "owen") {
    return SobolRandomization::owen;
  }
  throw InvalidArgumentError(
      "scramble", fmt::format("scramble: value is {}; rule: must be True (linear matrix scramble "
                              "+ digital shift, SciPy's), False or 'owen'",
                              std::string(py::repr(scramble))));
}

}  // namespace

void bind_samplers(py::module_& module) {
  py::class_<Sobol>(
      module, "Sobol",
      "The Sobol' sequence with Joe & Kuo's direction numbers (d <= 21201). Unscrambled, its "
      "points are bit-identical to scipy.stats.qmc.Sobol(d, scramble=False). scramble=True "
      "applies a random linear matrix scramble and digital shift (SciPy's method, drawn from "
      "twincal's own seeded stream, so the points differ from SciPy's); 'owen' nested uniform "
      "scrambling. The default seed is 0: scrambled points are reproducible unless you choose "
      "another.")
      .def(py::init([](Index d, const py::object& scramble, std::uint64_t seed,
                       const std::optional<int>& bits) {
             SobolOptions options;
             options.randomization = parse_scramble(scramble);
             options.seed = seed;
             if (bits) options.bits = *bits;
             options.warning_handler = warn;
             return Sobol(d, options);
           }),
           py::arg("d"), py::kw_only(), py::arg("scramble") = true, py::arg("seed") = 0,
           py::arg("bits") = py::none())
      .def_property_readonly("d", &Sobol::dimension, "Dimension.")
      .def_property_readonly(
          "num_generated", [](const Sobol& s) { return s.position(); },
          "Points generated (or skipped) so far.")
      .def_property_readonly(
          "seed", [](const Sobol& s) { return s.options().seed; }, "Seed of the scrambling.")
      .def_property_readonly(
          "bits", [](const Sobol& s) { return s.options().bits; },
          "Bits per coordinate: the sequence has 2^bits points.")
      .def("random", &draw<Sobol>, py::arg("n") = 1,
           "The next n points, an n x d array in [0, 1). Warns (UserWarning) unless n is a "
           "power of two that keeps the sequence's balance, as SciPy does.")
      .def(
          "random_base2",
          [](Sobol& s, int m) {
            if (m < 0 || m > s.options().bits) {
              throw InvalidArgumentError(
                  "m",
                  fmt::format("m: value is {}; rule: 0 <= m <= bits = {}", m, s.options().bits));
            }
            const std::uint64_t n = std::uint64_t{1} << m;
            if (!is_balanced_block(s.position(), n)) {
              throw InvalidArgumentError(
                  "m", fmt::format("m: {} points have been generated, then 2^{} = {}; rule: the "
                                   "balance of Sobol' points needs the position to be a multiple "
                                   "of 2^m (use random() to draw anyway)",
                                   s.position(), m, n));
            }
            return draw(s, static_cast<Index>(n));
          },
          py::arg("m"), "The next 2^m points (an n x d array); the block must keep the balance.")
      .def(
          "reset", [](Sobol& s) { s.seed(s.options().seed); },
          "Back to the first point, with the same scrambling.")
      .def(
          "fast_forward", [](Sobol& s, std::uint64_t n) { s.discard(n); }, py::arg("n"),
          "Skips n points.")
      .def("__repr__", [](const Sobol& s) {
        return fmt::format("Sobol(d={}, scramble={}, seed={}, bits={})", s.dimension(),
                           to_string(s.options().randomization), s.options().seed,
                           s.options().bits);
      });

  py::class_<Halton>(
      module, "Halton",
      "The Halton sequence. Unscrambled, its points are scipy.stats.qmc.Halton(d, "
      "scramble=False)'s; scramble=True permutes the digits (SciPy's scheme, twincal's seeded "
      "stream). The default seed is 0.")
      .def(py::init([](Index d, bool scramble, std::uint64_t seed) {
             HaltonOptions options;
             options.scramble = scramble;
             options.seed = seed;
             return Halton(d, options);
           }),
           py::arg("d"), py::kw_only(), py::arg("scramble") = true, py::arg("seed") = 0)
      .def_property_readonly("d", &Halton::dimension, "Dimension.")
      .def_property_readonly(
          "num_generated", [](const Halton& h) { return h.position(); },
          "Points generated (or skipped) so far.")
      .def_property_readonly(
          "seed", [](const Halton& h) { return h.options().seed; }, "Seed of the scrambling.")
      .def("random", &draw<Halton>, py::arg("n") = 1, "The next n points, an n x d array.")
      .def(
          "reset", [](Halton& h) { h.seed(h.options().seed); },
          "Back to the first point, with the same scrambling.")
      .def(
          "fast_forward", [](Halton& h, std::uint64_t n) { h.discard(n); }, py::arg("n"),
          "Skips n points.")
      .def("__repr__", [](const Halton& h) {
        return fmt::format("Halton(d={}, scramble={}, seed={})", h.dimension(),
                           h.options().scramble ? "True" : "False", h.options().seed);
      });
}

}  // namespace twincal::python
