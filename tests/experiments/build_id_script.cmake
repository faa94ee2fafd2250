# cmake/TwincalBuildId.cmake on a scratch git repository: the id names the commit, changes to
# tracked and new files add their hash, changes to the docs do not, and a tree without git is
# "unknown". Inputs: SCRIPT (the generator), SCRATCH (a directory to use).
cmake_minimum_required(VERSION 3.25)
find_program(GIT git REQUIRED)
file(REMOVE_RECURSE "${SCRATCH}")
set(repo "${SCRATCH}/repo")
file(MAKE_DIRECTORY "${repo}/src" "${repo}/docs" "${repo}/tests")
file(WRITE "${repo}/tests/a_test.cpp" "int t = 1;\n")
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

# Sets `id` and `commit` to what the script writes for SOURCE_DIR `dir`.
function(build_id dir)
  set(output "${SCRATCH}/id.inc")
  execute_process(COMMAND "${CMAKE_COMMAND}" "-DSOURCE_DIR=${dir}" "-DOUTPUT=${output}"
                          "-DCOMPILER=Clang 14.0.6" "-DBUILD_TYPE=Release" -P "${SCRIPT}"
                  RESULT_VARIABLE status ERROR_VARIABLE err)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "the script failed: ${err}")
  endif()
  file(READ "${output}" text)
  if(NOT text MATCHES "generated_build_id = \"([^\"]*)\";\nconstexpr std::string_view generated_build_commit = \"([^\"]*)\";")
    message(FATAL_ERROR "not the definitions: ${text}")
  endif()
  set(id "${CMAKE_MATCH_1}" PARENT_SCOPE)
  set(commit "${CMAKE_MATCH_2}" PARENT_SCOPE)
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
set(head "${git_out}")

build_id("${repo}")
set(clean "${id}")
if(NOT clean MATCHES "^sources [0-9a-f]+ \\(Clang 14.0.6, Release\\)$")
  message(FATAL_ERROR "a clean checkout: got ${clean}")
endif()
expect("${commit}" "${head}" "a clean checkout's commit")

# The docs and tests change neither the id nor the commit's "+changes", committed or not.
file(APPEND "${repo}/docs/guide.md" "More\n")
file(APPEND "${repo}/README.md" "More\n")
file(APPEND "${repo}/tests/a_test.cpp" "int u = 2;\n")
file(WRITE "${repo}/tests/b_test.cpp" "int v = 3;\n")
build_id("${repo}")
expect("${id}" "${clean}" "changed docs")
expect("${commit}" "${head}" "changed docs' commit")
git(add .)
git(commit -q -m docs)
git(rev-parse --short=12 HEAD)
set(docs_head "${git_out}")
build_id("${repo}")
expect("${id}" "${clean}" "a commit of the docs")
expect("${commit}" "${docs_head}" "a commit of the docs' commit")

# A changed source changes the id, the same way each time, and marks the commit.
file(APPEND "${repo}/src/a.cpp" "int b = 2;\n")
build_id("${repo}")
set(changed "${id}")
if(changed STREQUAL clean OR NOT changed MATCHES "^sources [0-9a-f]+ \\(Clang 14.0.6, Release\\)$")
  message(FATAL_ERROR "a changed source: got ${changed} (clean ${clean})")
endif()
expect("${commit}" "${docs_head}+changes" "a changed source's commit")
build_id("${repo}")
expect("${id}" "${changed}" "the same change again")
# Committed, the change keeps its id (the sources are what they were).
git(commit -q -a -m code)
build_id("${repo}")
expect("${id}" "${changed}" "the change committed")

# New files count, with their content.
file(WRITE "${repo}/src/new.cpp" "int c = 3;\n")
build_id("${repo}")
set(with_new "${id}")
if(with_new STREQUAL changed)
  message(FATAL_ERROR "a new file is not in the id: ${with_new}")
endif()
file(WRITE "${repo}/src/new.cpp" "int c = 4;\n")
build_id("${repo}")
if(id STREQUAL with_new)
  message(FATAL_ERROR "a new file's content is not in the id: ${id}")
endif()

# Without git: unknown. The scratch directory may sit inside another checkout (the build tree
# of one), which is not the sources'.
file(MAKE_DIRECTORY "${SCRATCH}/plain")
build_id("${SCRATCH}/plain")
expect("${id}" "unknown sources (Clang 14.0.6, Release)" "no git")
expect("${commit}" "unknown" "no git's commit")
file(REMOVE_RECURSE "${SCRATCH}")
