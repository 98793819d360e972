# SPDX-License-Identifier: MIT
# The README's dependency table, checked on the includes of SOURCE_DIR. Each
# rule names a folder and the headers it may not include (our include roots:
# dsp/ estimator/ hal/ hal/linux/ firmware/ sim_target/, the host-only
# toml_text/, and the host tools' sim_run/ audit/ recording/ can/). tools/
# and tests/ may include anything.
# RULE=<name> checks one rule only (the fixtures' tests).
set(_tools "sim_run|audit|recording|can")
set(rules dsp estimator hal hal_interfaces firmware sim_target toml_text)
set(dir_dsp dsp)
set(bad_dsp "estimator|hal|firmware|sim_target|toml_text|${_tools}")
set(dir_estimator estimator)
set(bad_estimator "dsp|hal|firmware|sim_target|toml_text|${_tools}")
set(dir_hal hal)
set(bad_hal "dsp|estimator|firmware|sim_target|toml_text|${_tools}")
set(dir_hal_interfaces hal/include)
set(bad_hal_interfaces "hal/linux")
set(dir_firmware firmware)
set(bad_firmware "hal/linux|sim_target|${_tools}")
set(dir_sim_target sim_target)
set(bad_sim_target "dsp|estimator|firmware|hal/linux|${_tools}")
# toml++ behind its guard (the scenario and calibration readers use it).
set(dir_toml_text toml_text)
set(bad_toml_text "dsp|estimator|hal|firmware|sim_target|${_tools}")

if(DEFINED RULE)
  set(rules ${RULE})
endif()
set(bad 0)
foreach(rule IN LISTS rules)
  set(dir ${dir_${rule}})
  file(GLOB_RECURSE files ${SOURCE_DIR}/${dir}/*.hpp ${SOURCE_DIR}/${dir}/*.cpp
       ${SOURCE_DIR}/${dir}/*.h ${SOURCE_DIR}/${dir}/*.c)
  foreach(f IN LISTS files)
    file(STRINGS ${f} lines REGEX "^[ \t]*#[ \t]*include")
    foreach(line IN LISTS lines)
      if(line MATCHES "[<\"](${bad_${rule}})/")
        message(NOTICE "layering: ${f} includes a forbidden header (rule ${rule}: ${dir}/ "
                           "may not include ${bad_${rule}}): ${line}")
        set(bad 1)
      endif()
    endforeach()
  endforeach()
endforeach()
if(bad)
  message(FATAL_ERROR "layering: see the dependency table in README.md")
endif()
