# The ready-made configs pass `twincal run|sweep --dry-run` (ctest apps.ready_made_configs): every
# *.json under each folder of CONFIG_DIRS (apps/sweeps and examples/, joined by "|") is parsed,
# validated and expanded into its groups the way the commands read it, without starting any
# program; a folder without one fails. A config whose twin is a program names it relative to its
# own folder, so each is read from there.
#   cmake -DTWINCAL=<twincal> -DCONFIG_DIRS=<dir>|<dir> -DWORK_DIR=<scratch> -P check_configs.cmake
foreach(variable TWINCAL CONFIG_DIRS WORK_DIR)
  if(NOT DEFINED ${variable})
    message(FATAL_ERROR "check_configs.cmake: -D${variable}= is missing")
  endif()
endforeach()
string(REPLACE "|" ";" folders "${CONFIG_DIRS}")
set(configs "")
foreach(folder IN LISTS folders)
  file(GLOB_RECURSE found "${folder}/*.json")
  if(NOT found)
    message(FATAL_ERROR "check_configs.cmake: no *.json under ${folder}")
  endif()
  list(APPEND configs ${found})
endforeach()
list(SORT configs)
list(LENGTH configs count)
file(REMOVE_RECURSE "${WORK_DIR}")
set(failures "")
foreach(config IN LISTS configs)
  get_filename_component(folder "${config}" DIRECTORY)
  file(READ "${config}" text)
  # A sweep document has a base and axes (docs/cli.md); anything else is one run's config.
  if(text MATCHES "\"axes\"[ \t\r\n]*:")
    set(command sweep)
  else()
    set(command run)
  endif()
  string(MAKE_C_IDENTIFIER "${config}" scratch)
  execute_process(
    COMMAND "${TWINCAL}" ${command} --config "${config}" --dry-run --quiet
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
  message(FATAL_ERROR "ready-made configs that twincal refuses:${failures}")
endif()
message(STATUS "${count} ready-made configs pass twincal's dry run")
