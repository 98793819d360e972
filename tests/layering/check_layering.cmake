# SPDX-License-Identifier: MIT
# Fails when a file under dsp/ or estimator/ of SOURCE_DIR includes a header
# from hal/, firmware/ or sim_target/ (or a tools/ header).
set(bad 0)
foreach(dir IN ITEMS dsp estimator)
  file(GLOB_RECURSE files ${SOURCE_DIR}/${dir}/*.hpp ${SOURCE_DIR}/${dir}/*.cpp
       ${SOURCE_DIR}/${dir}/*.h ${SOURCE_DIR}/${dir}/*.c)
  foreach(f IN LISTS files)
    file(STRINGS ${f} lines REGEX "^[ \t]*#[ \t]*include")
    foreach(line IN LISTS lines)
      if(line MATCHES "[<\"](hal|firmware|sim_target|tools)/")
        message(SEND_ERROR "layering: ${f} includes a forbidden header: ${line}")
        set(bad 1)
      endif()
    endforeach()
  endforeach()
endforeach()
if(bad)
  message(FATAL_ERROR "dsp/ and estimator/ may include only the standard library, Eigen and dsp/")
endif()
