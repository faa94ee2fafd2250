# Run at every build (cmake -P, from core/CMakeLists.txt): writes OUTPUT, the C++ string literal
# of the build's identity — the commit, a hash of the uncommitted changes to anything but the
# docs (new files included), the compiler and the build type — and leaves it untouched while that is unchanged, so
# only core's build_id.cpp recompiles when it changes. Without git (a source tarball) the commit
# is "unknown".
# Inputs: SOURCE_DIR, OUTPUT, COMPILER, BUILD_TYPE.
cmake_minimum_required(VERSION 3.25)
# Only the sources' own checkout counts: a tarball unpacked inside another repository is not it.
execute_process(
  COMMAND git -C "${SOURCE_DIR}" rev-parse --show-toplevel --short=12 HEAD
  OUTPUT_VARIABLE lines RESULT_VARIABLE status OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
set(commit "")
if(status EQUAL 0)
  string(REPLACE "\n" ";" lines "${lines}")
  list(GET lines 0 toplevel)
  list(GET lines -1 commit)
  file(REAL_PATH "${SOURCE_DIR}" source_path)
  file(REAL_PATH "${toplevel}" toplevel)
  if(NOT toplevel STREQUAL source_path)
    set(commit "")
  endif()
endif()
if(commit STREQUAL "")
  set(source "unknown")
else()
  # The docs do not change what a build computes; every other tracked file may.
  execute_process(
    COMMAND git -C "${SOURCE_DIR}" diff HEAD --no-ext-diff --binary -- .
            ":(exclude)docs" ":(exclude)*.md"
    OUTPUT_VARIABLE changes RESULT_VARIABLE status ERROR_QUIET)
  # New files git does not track yet (and does not ignore) count as changes too.
  execute_process(
    COMMAND git -C "${SOURCE_DIR}" ls-files --others --exclude-standard -- .
            ":(exclude)docs" ":(exclude)*.md"
    OUTPUT_VARIABLE untracked RESULT_VARIABLE untracked_status
    OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(untracked_status EQUAL 0 AND NOT untracked STREQUAL "")
    string(REPLACE "\n" ";" untracked "${untracked}")
    foreach(file IN LISTS untracked)
      if(EXISTS "${SOURCE_DIR}/${file}" AND NOT IS_DIRECTORY "${SOURCE_DIR}/${file}")
        file(SHA1 "${SOURCE_DIR}/${file}" file_hash)
        string(APPEND changes "${file} ${file_hash}\n")
      endif()
    endforeach()
  endif()
  if(NOT status EQUAL 0)
    set(source "${commit}+unknown")
  elseif(changes STREQUAL "")
    set(source "${commit}")
  else()
    string(SHA1 hash "${changes}")
    string(SUBSTRING "${hash}" 0 12 hash)
    set(source "${commit}+${hash}")
  endif()
endif()
if(BUILD_TYPE STREQUAL "")
  set(BUILD_TYPE "no build type")
endif()
set(TWINCAL_BUILD_ID "${source} (${COMPILER}, ${BUILD_TYPE})")
file(CONFIGURE OUTPUT "${OUTPUT}" CONTENT "\"@TWINCAL_BUILD_ID@\"\n" @ONLY)
