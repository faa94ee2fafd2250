# cmake/TwincalBuildId.cmake on a scratch git repository: the id names the commit, changes to
# tracked and new files add their hash, changes to the docs do not, and a tree without git is
# "unknown". Inputs: SCRIPT (the generator), SCRATCH (a directory to use).
cmake_minimum_required(VERSION 3.25)
find_program(GIT git REQUIRED)
file(REMOVE_RECURSE "${SCRATCH}")
set(repo "${SCRATCH}/repo")
file(MAKE_DIRECTORY "${repo}/src" "${repo}/docs")
file(WRITE "${repo}/src/a.cpp" "int a = 1;\n")
file(WRITE "${repo}/docs/guide.md" "Guide\n")
file(WRITE "${repo}/README.md" "Read me\n")

function(git)
  execute_process(COMMAND "${GIT}" -C "${repo}" -c user.name=test -c user.email=test@example.com
                          ${ARGN} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err
                          OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "git ${ARGN}: ${err}")
  endif()
  set(git_out "${out}" PARENT_SCOPE)
endfunction()

# Sets `id` to the id the script writes for SOURCE_DIR `dir`.
function(build_id dir)
  set(output "${SCRATCH}/id.inc")
  execute_process(COMMAND "${CMAKE_COMMAND}" "-DSOURCE_DIR=${dir}" "-DOUTPUT=${output}"
                          "-DCOMPILER=Clang 14.0.6" "-DBUILD_TYPE=Release" -P "${SCRIPT}"
                  RESULT_VARIABLE status ERROR_VARIABLE err)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "the script failed: ${err}")
  endif()
  file(READ "${output}" text)
  string(STRIP "${text}" text)
  set(id "${text}" PARENT_SCOPE)
endfunction()

function(expect actual expected what)
  if(NOT actual STREQUAL expected)
    message(FATAL_ERROR "${what}: got ${actual}, expected ${expected}")
  endif()
endfunction()

git(init -q)
git(add .)
git(commit -q -m first)
git(rev-parse --short=12 HEAD)
set(commit "${git_out}")

build_id("${repo}")
expect("${id}" "\"${commit} (Clang 14.0.6, Release)\"" "a clean checkout")

file(APPEND "${repo}/docs/guide.md" "More\n")
file(APPEND "${repo}/README.md" "More\n")
build_id("${repo}")
expect("${id}" "\"${commit} (Clang 14.0.6, Release)\"" "changed docs")

file(APPEND "${repo}/src/a.cpp" "int b = 2;\n")
build_id("${repo}")
set(changed "${id}")
if(NOT changed MATCHES "^\"${commit}\\+[0-9a-f]+ \\(Clang 14.0.6, Release\\)\"$")
  message(FATAL_ERROR "a changed source: got ${changed}")
endif()
build_id("${repo}")
expect("${id}" "${changed}" "the same change again")

file(WRITE "${repo}/src/new.cpp" "int c = 3;\n")
build_id("${repo}")
if(id STREQUAL changed OR NOT id MATCHES "^\"${commit}\\+")
  message(FATAL_ERROR "a new file: got ${id} (before it ${changed})")
endif()
set(with_new "${id}")
file(WRITE "${repo}/src/new.cpp" "int c = 4;\n")
build_id("${repo}")
if(id STREQUAL with_new)
  message(FATAL_ERROR "a new file's content is not in the id: ${id}")
endif()

file(MAKE_DIRECTORY "${SCRATCH}/plain")
build_id("${SCRATCH}/plain")
expect("${id}" "\"unknown (Clang 14.0.6, Release)\"" "no git")
file(REMOVE_RECURSE "${SCRATCH}")
