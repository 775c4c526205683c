# Cross build for the reference MCU, STM32F103 (Cortex-M3, no FPU).
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_ASM_COMPILER arm-none-eabi-gcc)
set(CMAKE_OBJCOPY arm-none-eabi-objcopy CACHE FILEPATH "")
set(CMAKE_SIZE arm-none-eabi-size CACHE FILEPATH "")
set(CMAKE_NM arm-none-eabi-nm CACHE FILEPATH "")
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

# SERVO_CPU: cortex-m3 (the reference MCU) or cortex-m0 (the target
# benchmark's second build, tests/bench/target).
if(NOT DEFINED SERVO_CPU)
  set(SERVO_CPU cortex-m3)
endif()
set(SERVO_CPU_FLAGS "-mcpu=${SERVO_CPU} -mthumb -mfloat-abi=soft")
set(CMAKE_C_FLAGS_INIT "${SERVO_CPU_FLAGS} -ffunction-sections -fdata-sections -fno-common -fstack-usage -fcallgraph-info=su")
set(CMAKE_EXE_LINKER_FLAGS_INIT
    "${SERVO_CPU_FLAGS} -nostartfiles --specs=nano.specs --specs=nosys.specs -Wl,--gc-sections")

set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
