/// \file
/// The library's version, for code that builds against more than one
/// (CMakeLists.txt reads the project version from here).
#pragma once

/// Major version: 0 while the API may still change between minor versions.
#define ZWANG_VERSION_MAJOR 0
/// Minor version. 0.2: one argument order (model, ws, q, qd, tau, task, ...),
/// forwardDynamics, frame queries that take the state (docs/getting-started.md).
#define ZWANG_VERSION_MINOR 2
/// Patch version.
#define ZWANG_VERSION_PATCH 0

/// True when the library is at least version major.minor.patch.
#define ZWANG_VERSION_AT_LEAST(major, minor, patch)                                                      \
  (ZWANG_VERSION_MAJOR > (major) || (ZWANG_VERSION_MAJOR == (major) && ZWANG_VERSION_MINOR > (minor)) || \
   (ZWANG_VERSION_MAJOR == (major) && ZWANG_VERSION_MINOR == (minor) && ZWANG_VERSION_PATCH >= (patch)))
