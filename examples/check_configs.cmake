# Every config and sweep file of examples/ passes `twincal run|sweep --dry-run`: parsed, validated
# and expanded into its groups the way the commands read them, without starting any program (a
# config whose twin is a program names it relative to its own folder, so each is read from there).
#   cmake -DTWINCAL=<twincal> -DEXAMPLES_DIR=<examples> -DWORK_DIR=<scratch> -P check_configs.cmake
foreach(variable TWINCAL EXAMPLES_DIR WORK_DIR)
  if(NOT DEFINED ${variable})
    message(FATAL_ERROR "check_configs.cmake: -D${variable}= is missing")
  endif()
endforeach()
file(GLOB_RECURSE configs RELATIVE "${EXAMPLES_DIR}" "${EXAMPLES_DIR}/*.json")
list(SORT configs)
list(LENGTH configs count)
if(count EQUAL 0)
  message(FATAL_ERROR "check_configs.cmake: no *.json under ${EXAMPLES_DIR}")
endif()
file(REMOVE_RECURSE "${WORK_DIR}")
set(failures "")
foreach(config IN LISTS configs)
  get_filename_component(folder "${EXAMPLES_DIR}/${config}" DIRECTORY)
  file(READ "${EXAMPLES_DIR}/${config}" text)
  # A sweep document has a base and axes (docs/cli.md); anything else is one run's config.
  if(text MATCHES "\"axes\"[ \t\r\n]*:")
    set(command sweep)
  else()
    set(command run)
  endif()
  string(MAKE_C_IDENTIFIER "${config}" scratch)
  execute_process(
    COMMAND "${TWINCAL}" ${command} --config "${EXAMPLES_DIR}/${config}" --dry-run --quiet
            --out "${WORK_DIR}/${scratch}"
    WORKING_DIRECTORY "${folder}"
    RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT status EQUAL 0)
    string(APPEND failures "\n  ${config} (twincal ${command}): status ${status}: ${err}")
  elseif(NOT out MATCHES "[1-9][0-9]* groups?, [1-9][0-9]* episodes")
    string(APPEND failures "\n  ${config} (twincal ${command}): no groups listed:\n${out}")
  endif()
endforeach()
if(failures)
  message(FATAL_ERROR "example configs that twincal refuses:${failures}")
endif()
message(STATUS "${count} example configs pass twincal's dry run")
