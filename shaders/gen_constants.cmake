# Writes skinpack_constants.glsl: every integer #define SP_* and every SP_METHOD_* enumerator of
# native/include/skinpack.h as a GLSL #define, so shaders and C cannot drift apart.
#   cmake -DHEADER=.../skinpack.h -DOUTPUT=.../skinpack_constants.glsl -P gen_constants.cmake
if(NOT HEADER OR NOT OUTPUT)
  message(FATAL_ERROR "gen_constants.cmake needs -DHEADER=<skinpack.h> -DOUTPUT=<file>")
endif()
file(READ "${HEADER}" header_text)

set(lines "// Generated from ${HEADER} by shaders/gen_constants.cmake. Do not edit.\n")
string(APPEND lines "#ifndef SKINPACK_CONSTANTS_GLSL\n#define SKINPACK_CONSTANTS_GLSL\n")

# Object-like macros with a plain decimal value: SP_MAX_INFLUENCES, SP_MAX_WEIGHT_BITS, ...
string(REGEX MATCHALL "#define[ \t]+SP_[A-Z0-9_]+[ \t]+[0-9]+" defines "${header_text}")
foreach(define IN LISTS defines)
  string(REGEX REPLACE "#define[ \t]+(SP_[A-Z0-9_]+)[ \t]+([0-9]+)" "\\1;\\2" pair "${define}")
  list(GET pair 0 name)
  list(GET pair 1 value)
  string(APPEND lines "#define ${name} ${value}u\n")
endforeach()

# Enumerators with explicit values: SP_METHOD_FIXED = 0, ...
string(REGEX MATCHALL "SP_METHOD_[A-Z0-9_]+[ \t]*=[ \t]*[0-9]+" enumerators "${header_text}")
list(LENGTH enumerators enumerator_count)
if(enumerator_count EQUAL 0)
  message(FATAL_ERROR "gen_constants.cmake: no SP_METHOD_* enumerators in ${HEADER}")
endif()
foreach(enumerator IN LISTS enumerators)
  string(REGEX REPLACE "(SP_METHOD_[A-Z0-9_]+)[ \t]*=[ \t]*([0-9]+)" "\\1;\\2" pair "${enumerator}")
  list(GET pair 0 name)
  list(GET pair 1 value)
  string(APPEND lines "#define ${name} ${value}u\n")
endforeach()
# SP_METHOD_COUNT follows the last explicit enumerator without a value.
list(LENGTH enumerators method_count)
string(APPEND lines "#define SP_METHOD_COUNT ${method_count}u\n")
string(APPEND lines "#endif\n")

# Rewrite only on change so shaders are not recompiled on every build.
if(EXISTS "${OUTPUT}")
  file(READ "${OUTPUT}" old_text)
  if(old_text STREQUAL lines)
    return()
  endif()
endif()
file(WRITE "${OUTPUT}" "${lines}")
