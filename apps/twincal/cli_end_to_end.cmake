# End-to-end test of the twincal CLI (ctest apps.cli_end_to_end): a tiny study, an interrupted
# run resumed, a rerun that skips everything, another thread count, a conflicting config, the
# summary, every --help, and the external case with 1 and 3 worker processes (the ready-made
# sweeps and configs are dry-run by apps.ready_made_configs, check_configs.cmake). Results are compared without their wall-time columns.
#   cmake -DTWINCAL=<twincal> -DWORK_DIR=<scratch>
#         -DEXTERNAL_DIR=<examples/external_twin> -DPYTHON=<python3> -P cli_end_to_end.cmake

file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")
set(study run --case analytic --locators ABC --runs 2 --assemblies 10
    --controllers baseline,default,w=0.5,w=1 --quiet)

function(twincal_ok)
  execute_process(COMMAND "${TWINCAL}" ${ARGN} RESULT_VARIABLE status OUTPUT_VARIABLE out
    ERROR_VARIABLE err)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "twincal ${ARGN} failed (${status}):\n${out}\n${err}")
  endif()
  set(output "${out}" PARENT_SCOPE)
endfunction()

# The results without wall times: the seconds column of the CSV and seconds_per_assembly.
function(read_results dir out_var)
  file(READ "${dir}/assemblies.csv" rows)
  string(REGEX REPLACE ",[^,\n]*\n" "\n" rows "${rows}")
  file(READ "${dir}/episodes.jsonl" episodes)
  string(REGEX REPLACE "\"seconds_per_assembly\":[^,]*," "" episodes "${episodes}")
  string(REGEX MATCHALL "\n" row_lines "${rows}")
  string(REGEX MATCHALL "\n" episode_lines "${episodes}")
  list(LENGTH row_lines row_count)
  list(LENGTH episode_lines episode_count)
  set(${out_var} "${rows}${episodes}" PARENT_SCOPE)
  set(${out_var}_rows ${row_count} PARENT_SCOPE)
  set(${out_var}_episodes ${episode_count} PARENT_SCOPE)
endfunction()

# The study on 2 threads into a/, whose output must match `progress` (else it fails with
# `failure`), its results read into `results` (read_results). A macro, so that `output` and the
# results land in the caller's scope.
macro(run_study_into_a progress failure results)
  twincal_ok(${study} --threads 2 --out "${WORK_DIR}/a")
  if(NOT output MATCHES "${progress}")
    message(FATAL_ERROR "${failure}:\n${output}")
  endif()
  read_results("${WORK_DIR}/a" ${results})
endmacro()

# 1. The study: 2 runs x 4 controllers x 10 assemblies.
run_study_into_a("8 episodes: 8 run now, 0 already" "first run did not run 8 episodes" first)
if(NOT first_rows EQUAL 81 OR NOT first_episodes EQUAL 8)
  message(FATAL_ERROR "expected 1 + 80 CSV rows and 8 episodes, got ${first_rows} and "
    "${first_episodes}")
endif()

# 2. A rerun skips every finished episode and changes nothing.
run_study_into_a("8 episodes: 0 run now, 8 already" "rerun did not skip the finished episodes"
  second)
if(NOT first STREQUAL second)
  message(FATAL_ERROR "a rerun changed the results")
endif()

# 3. An interrupted run: keep 3 episode records (the CSV still holds all 8 episodes' rows, as
#    after a kill between the CSV and the record); the resume redoes 5 and ends where 1 did.
file(STRINGS "${WORK_DIR}/a/episodes.jsonl" records)
list(SUBLIST records 0 3 kept)
list(JOIN kept "\n" kept_text)
file(WRITE "${WORK_DIR}/a/episodes.jsonl" "${kept_text}\n")
run_study_into_a("8 episodes: 5 run now, 3 already" "resume did not run the 5 missing episodes"
  resumed)
if(NOT first STREQUAL resumed)
  message(FATAL_ERROR "the resumed results differ from the uninterrupted ones")
endif()

# 4. One thread gives the same results, in the same order.
twincal_ok(${study} --threads 1 --out "${WORK_DIR}/b")
read_results("${WORK_DIR}/b" single)
if(NOT first STREQUAL single)
  message(FATAL_ERROR "--threads 1 and --threads 2 give different results")
endif()

# 5. A different config for a stored group is refused, naming the setting.
execute_process(COMMAND "${TWINCAL}" ${study} --seed 7 --out "${WORK_DIR}/a"
  RESULT_VARIABLE status ERROR_VARIABLE err OUTPUT_QUIET)
if(status EQUAL 0 OR NOT err MATCHES "seed was 2023, is now 7")
  message(FATAL_ERROR "a conflicting config was not refused (${status}): ${err}")
endif()

# The version names the build that results directories record.
twincal_ok(--version)
if(NOT output MATCHES "^twincal [0-9]+\\.[0-9]+\\.[0-9]+\nbuild: (sources [0-9a-f]+|unknown sources) \\(.+\\)\ncommit: ")
  message(FATAL_ERROR "twincal --version printed:\n${output}")
endif()
file(READ "${WORK_DIR}/a/summary.json" summary)
string(JSON recorded GET "${summary}" groups 0 build)
string(FIND "${output}" "build: ${recorded}\n" at)
if(at EQUAL -1)
  message(FATAL_ERROR "the results record build '${recorded}', twincal --version says:\n${output}")
endif()

# 6. The summary, and --help everywhere.
twincal_ok(summary --results "${WORK_DIR}/a")
if(NOT output MATCHES "analytic/ABC +w=1 +2 ")
  message(FATAL_ERROR "summary lacks the w=1 row:\n${output}")
endif()
foreach(command run paper scaling sweep plot summary trace)
  twincal_ok(${command} --help)
  if(NOT output MATCHES "usage: twincal ${command}")
    message(FATAL_ERROR "twincal ${command} --help printed:\n${output}")
  endif()
endforeach()
# The config options' help is generated from their table: choices from the enums' name tables,
# defaults from ExperimentConfig{} (config_options.cpp).
twincal_ok(run --help)
foreach(line
    "--filter NAME +sigma points of the filter: merwe [|] julier [|] cubature [|] fifth_degree [|]"
    "simplex [(]merwe: the paper's UKF; cubature: CKF; default merwe[)]"
    "--runs N +runs per controller [(]default 10[)]"
    "--twin-workers N +processes of the external twin [(]default 1;")
  if(NOT output MATCHES "${line}")
    message(FATAL_ERROR "twincal run --help lacks '${line}':\n${output}")
  endif()
endforeach()

# 6b. `twincal trace` runs one episode of the study exactly as `run` did: its z column is the
# study's, digit for digit; two controllers are refused.
twincal_ok(trace --case analytic --locators ABC --assemblies 10 --controller w=1 --run 1
  --out "${WORK_DIR}/trace.csv")
execute_process(COMMAND "${PYTHON}" -c "
import csv, sys
trace = [row['z'] for row in csv.DictReader(open(sys.argv[1]))]
study = [row['z'] for row in csv.DictReader(open(sys.argv[2]))
         if row['group'] == 'analytic/ABC' and row['controller'] == 'w=1' and row['run'] == '1']
sys.exit(0 if len(trace) == 10 and trace == study else f'trace {trace} != study {study}')
" "${WORK_DIR}/trace.csv" "${WORK_DIR}/a/assemblies.csv" RESULT_VARIABLE status
  ERROR_VARIABLE err)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "twincal trace is not the study's episode: ${err}")
endif()
execute_process(COMMAND "${TWINCAL}" trace --case analytic --controllers baseline,active
  RESULT_VARIABLE status OUTPUT_QUIET ERROR_VARIABLE err)
if(status EQUAL 0 OR NOT err MATCHES "names 2 controllers; rule: trace runs one")
  message(FATAL_ERROR "trace of two controllers was not refused (${status}): ${err}")
endif()

# 7. Configs that once crashed or wrapped: 200 000 levels of nesting (SIGSEGV) and a run count
# whose episodes overflowed ("-2 episodes") are refused with the rule they break.
string(REPEAT "[" 200000 deep)
file(WRITE "${WORK_DIR}/deep.json" "{\"case\": ${deep}}")
file(WRITE "${WORK_DIR}/runs.json" "{\"runs\": 9223372036854775807}")
file(WRITE "${WORK_DIR}/twice.json" "{\"runs\": 2, \"runs\": 3}")
file(WRITE "${WORK_DIR}/coerced.json" "{\"runs\": 2.9}")
foreach(pair "deep.json|nests 200001 levels of arrays and objects; rule: at most 64"
             "runs.json|runs: value is 9223372036854775807; rule: must lie in [1, 1000000]"
             "twice.json|the key \"runs\" appears twice in one object"
             "coerced.json|runs: is 2.9; rule: an integer")
  string(REPLACE "|" ";" pair "${pair}")
  list(GET pair 0 config)
  list(GET pair 1 expected)
  execute_process(COMMAND "${TWINCAL}" run --config "${WORK_DIR}/${config}" --dry-run
    RESULT_VARIABLE status ERROR_VARIABLE err OUTPUT_QUIET)
  string(FIND "${err}" "${expected}" found)
  if(NOT status EQUAL 1 OR found EQUAL -1)
    message(FATAL_ERROR "run --config ${config} --dry-run: status ${status}, printed:\n${err}")
  endif()
endforeach()

# A dry run starts no twin program: checking an untrusted config executes none of it (a program
# that cannot exist would fail at its start).
file(WRITE "${WORK_DIR}/never_started.json"
  "{\"case\": \"external\", \"locators\": \"ABC\", \"external_twin\": {\"command\": "
  "[\"${WORK_DIR}/no-such-twin\"], \"locators\": [\"p\", \"q\", \"r\", \"s\"], "
  "\"lower_bounds\": [-1, -1, -1, -1], \"upper_bounds\": [1, 1, 1, 1]}}")
twincal_ok(run --config "${WORK_DIR}/never_started.json" --dry-run)
if(NOT output MATCHES "locators \\[p, q, r\\], 10 runs")
  message(FATAL_ERROR "dry run of an external config printed:\n${output}")
endif()

# A repeated option is a mistake, not an override.
execute_process(COMMAND "${TWINCAL}" run --runs 2 --runs 3 --dry-run
  RESULT_VARIABLE status ERROR_VARIABLE err OUTPUT_QUIET)
if(NOT status EQUAL 1 OR NOT err MATCHES "--runs: is given more than once")
  message(FATAL_ERROR "run --runs 2 --runs 3: status ${status}, printed:\n${err}")
endif()

# 8. The external case: the minimal twin of examples/external_twin (a Python program) gives the
# same episodes with 1 and 3 worker processes, and --twin-command overrides the config's.
# 4 × 5 assemblies keep the u0 searches short.
file(READ "${EXTERNAL_DIR}/config.json" external_config)
string(JSON external_config SET "${external_config}" external_twin upper_parts 4)
string(JSON external_config SET "${external_config}" external_twin lower_parts 5)
file(WRITE "${WORK_DIR}/external.json" "${external_config}")
set(external run --config "${WORK_DIR}/external.json" --runs 1 --assemblies 8
    --controllers baseline,w=1,active --threads 1 --quiet
    --twin-command "${PYTHON} ${EXTERNAL_DIR}/minimal_twin.py")
twincal_ok(${external} --twin-workers 1 --out "${WORK_DIR}/external1")
read_results("${WORK_DIR}/external1" external_one)
twincal_ok(${external} --twin-workers 3 --out "${WORK_DIR}/external3")
read_results("${WORK_DIR}/external3" external_three)
if(NOT external_one_episodes EQUAL 3 OR NOT external_one STREQUAL external_three)
  message(FATAL_ERROR "the external twin with 1 and 3 workers gives different results")
endif()
execute_process(COMMAND "${TWINCAL}" run --case external --out "${WORK_DIR}/external_bad"
  --twin-workers 2 RESULT_VARIABLE status ERROR_VARIABLE err OUTPUT_QUIET)
if(status EQUAL 0 OR NOT err MATCHES "--twin-workers: the config has no external_twin")
  message(FATAL_ERROR "--twin-workers without an external_twin was not refused:\n${err}")
endif()
