# Run at every build (cmake -P, from apps/experiments/CMakeLists.txt): writes OUTPUT, the C++
# definitions of build_id() and build_commit() (twincal/experiments/build_id.hpp), and leaves it
# untouched while they are unchanged, so only src/build_id.cpp recompiles when they change.
# - The id: a hash of the sources — every file git tracks but the docs, tests, benchmarks, fuzz
#   targets and CI scripts, as they are in the working tree, and the new files git does not
#   ignore — with the compiler and the build type. A commit that changes only those keeps it.
# - The commit: HEAD's (12 hex digits), "+changes" with uncommitted changes to the sources.
# Outside a git checkout of SOURCE_DIR (a source tarball) both say "unknown".
# Inputs: SOURCE_DIR, OUTPUT, COMPILER, BUILD_TYPE.
cmake_minimum_required(VERSION 3.25)
# The build must not take the index lock a user's git command may need at the same moment.
set(ENV{GIT_OPTIONAL_LOCKS} 0)

function(run_git out_var)
  execute_process(COMMAND git -C "${SOURCE_DIR}" ${ARGN}
                  OUTPUT_VARIABLE out RESULT_VARIABLE status ERROR_QUIET)
  if(NOT status EQUAL 0)
    set(git_failed TRUE PARENT_SCOPE)
  endif()
  set(${out_var} "${out}" PARENT_SCOPE)
endfunction()

set(git_failed FALSE)
set(sources "")
# Only the sources' own checkout counts: a tarball unpacked inside another repository is not it.
run_git(toplevel rev-parse --show-toplevel)
string(STRIP "${toplevel}" toplevel)
if(NOT git_failed)
  file(REAL_PATH "${SOURCE_DIR}" source_path)
  file(REAL_PATH "${toplevel}" toplevel)
  if(NOT toplevel STREQUAL source_path)
    set(git_failed TRUE)
  endif()
endif()
if(NOT git_failed)
  # What cannot change what a build computes: the docs, and the tests, benchmarks, fuzz targets
  # and CI scripts, which are not part of the libraries or programs.
  set(pathspec -- . ":(exclude)docs" ":(exclude)*.md" ":(exclude)tests" ":(exclude)benchmarks"
               ":(exclude)fuzz" ":(exclude).ci")
  run_git(commit rev-parse --short=12 HEAD)
  run_git(changes diff HEAD --no-ext-diff --stat ${pathspec})
  run_git(untracked ls-files --others --exclude-standard ${pathspec})
  # The tracked files as they are: a commit of the working tree made without touching anything
  # (none when nothing changed), listed blob by blob, the docs left out.
  run_git(working -c user.name=twincal -c user.email=build@twincal.invalid stash create)
  string(STRIP "${working}" working)
  if(working STREQUAL "")
    set(working HEAD)
  endif()
  run_git(tree ls-tree -r "${working}")
  string(REGEX REPLACE "[^\n]*\t(docs|tests|benchmarks|fuzz|\\.ci)/[^\n]*\n" "" tree "${tree}")
  string(REGEX REPLACE "[^\n]*\t[^\n]*\\.md\n" "" tree "${tree}")
endif()
if(git_failed)
  set(id "unknown sources")
  set(commit "unknown")
else()
  string(STRIP "${commit}" commit)
  string(STRIP "${untracked}" untracked)
  set(new_files "")
  if(NOT untracked STREQUAL "")
    string(REPLACE "\n" ";" untracked "${untracked}")
    foreach(file IN LISTS untracked)
      if(EXISTS "${SOURCE_DIR}/${file}" AND NOT IS_DIRECTORY "${SOURCE_DIR}/${file}")
        file(SHA1 "${SOURCE_DIR}/${file}" file_hash)
        string(APPEND new_files "${file} ${file_hash}\n")
      endif()
    endforeach()
  endif()
  string(SHA1 hash "${tree}${new_files}")
  string(SUBSTRING "${hash}" 0 12 hash)
  set(id "sources ${hash}")
  if(NOT changes STREQUAL "" OR NOT new_files STREQUAL "")
    string(APPEND commit "+changes")
  endif()
endif()
if(BUILD_TYPE STREQUAL "")
  set(BUILD_TYPE "no build type")
endif()
set(TWINCAL_BUILD_ID "${id} (${COMPILER}, ${BUILD_TYPE})")
set(TWINCAL_BUILD_COMMIT "${commit}")
file(CONFIGURE OUTPUT "${OUTPUT}" CONTENT
"constexpr std::string_view generated_build_id = \"@TWINCAL_BUILD_ID@\";
constexpr std::string_view generated_build_commit = \"@TWINCAL_BUILD_COMMIT@\";
" @ONLY)
