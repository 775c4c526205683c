# A configure that stopped before it found the compiler (the fuzz and
# coverage presets' clang not installed yet) writes the build type's flags
# to the cache empty, and every later configure of that folder keeps them
# so: the fuzz preset then built without -O2, at a third of its speed,
# though its compile lines looked as they should. An empty entry where the
# compiler has defaults takes the defaults again. Only in the clang builds
# (fuzz, coverage), where it happens: elsewhere an empty entry is the user's.
if(CMAKE_BUILD_TYPE AND (SERVO_FUZZ OR SERVO_COVERAGE))
  string(TOUPPER "${CMAKE_BUILD_TYPE}" servo_build_type)
  foreach(lang IN ITEMS C)
    set(servo_flags_init "${CMAKE_${lang}_FLAGS_${servo_build_type}_INIT}")
    string(STRIP "${servo_flags_init}" servo_flags_init)
    if(DEFINED CACHE{CMAKE_${lang}_FLAGS_${servo_build_type}}
       AND "$CACHE{CMAKE_${lang}_FLAGS_${servo_build_type}}" STREQUAL ""
       AND NOT servo_flags_init STREQUAL "")
      message(STATUS "CMAKE_${lang}_FLAGS_${servo_build_type} was empty in the cache (a configure "
                     "that failed before it found the compiler): set to '${servo_flags_init}'")
      set(CMAKE_${lang}_FLAGS_${servo_build_type} "${servo_flags_init}" CACHE STRING
          "Flags used by the ${lang} compiler during ${CMAKE_BUILD_TYPE} builds." FORCE)
    endif()
  endforeach()
endif()
