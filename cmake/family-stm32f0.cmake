# The STM32F0 family's build settings (Cortex-M0): a board of it includes
# this from its board.cmake, then sets what differs (its sources, limits).
set(SERVO_BOARD_FAMILY stm32f0)
set(SERVO_BOARD_CPU cortex-m0)
set(SERVO_BOARD_PORT servo_stm32f0)                      # hal/ports/stm32f0
set(SERVO_BOARD_STARTUP ${PROJECT_SOURCE_DIR}/hal/ports/stm32f0/startup_stm32f030.c)
