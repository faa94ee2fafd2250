#pragma once
/// @file
/// `TwinWithKeptAssemblies`: a twin whose assemblies a controller may keep past the call it was
/// given them in, and evaluate again later (the active controller refits the models of
/// assemblies it measured earlier, active_controller.hpp). Value types such as AssemblyId
/// qualify; a twin whose Assembly only borrows an object for the duration of a call (the Python
/// binding's PythonAssembly) says so with `static constexpr bool borrows_assemblies = true;`, and
/// a wrapper twin forwards its inner twin's `borrows_assemblies_v`.

#include <concepts>

#include "twincal/models/twin.hpp"

namespace twincal {

/// Whether T declares that its assemblies are borrowed (see the file comment).
template <typename T>
inline constexpr bool borrows_assemblies_v = [] {
  if constexpr (requires { T::borrows_assemblies; }) {
    return static_cast<bool>(T::borrows_assemblies);
  } else {
    return false;
  }
}();

template <typename T>
concept TwinWithKeptAssemblies =
    Twin<T> && std::semiregular<typename T::Assembly> && !borrows_assemblies_v<T>;

}  // namespace twincal
