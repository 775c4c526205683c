# The STM32G0 family's build settings (Cortex-M0+): a board of it includes
# this from its board.cmake, then sets what differs (its sources, limits).
# Its boards build in the arm-g0 preset (SERVO_CPU cortex-m0plus).
set(SERVO_BOARD_FAMILY stm32g0)
set(SERVO_BOARD_CPU cortex-m0plus)
set(SERVO_BOARD_PORT servo_stm32g0)                      # hal/ports/stm32g0
set(SERVO_BOARD_PORT_LIBS servo_stm32g0)                 # it compiles the shared drivers itself
set(SERVO_BOARD_STARTUP ${PROJECT_SOURCE_DIR}/hal/ports/stm32g0/startup_stm32g031.c)
