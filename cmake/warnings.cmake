# Warnings for firmware code: every integer conversion must be deliberate.
set(SERVO_FIRMWARE_WARNINGS
    -Wall -Wextra -Werror -Wpedantic
    -Wconversion -Wsign-conversion -Wshadow -Wcast-qual -Wcast-align
    -Wstrict-prototypes -Wmissing-prototypes -Wundef -Wdouble-promotion
    -Wfloat-equal -Wformat=2 -Wswitch-default -Wvla -Wnull-dereference
    -Wredundant-decls -Wwrite-strings)

# Tests and tools: strict, but cmocka's macros convert freely.
set(SERVO_TEST_WARNINGS -Wall -Wextra -Werror -Wshadow -Wno-unused-parameter)

# A firmware target: its warnings, and on a size-first image (the Cortex-M0)
# SERVO_SIZE_FIRST, where the per-tick helpers are called rather than inlined.
# Public: it shapes structs too (struct profile has no smoothing fields
# there), so whatever links a firmware library (the target benchmark) sees
# them as it does.
function(servo_firmware_target target)
  target_compile_options(${target} PRIVATE ${SERVO_FIRMWARE_WARNINGS})
  if(SERVO_SIZE_FIRST)
    target_compile_definitions(${target} PUBLIC SERVO_SIZE_FIRST)
  endif()
endfunction()
