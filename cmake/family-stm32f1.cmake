# The STM32F1 family's build settings (Cortex-M3): a board of it includes
# this from its board.cmake, then sets what differs (its sources, limits).
set(SERVO_BOARD_FAMILY stm32f1)
set(SERVO_BOARD_CPU cortex-m3)
set(SERVO_BOARD_PORT servo_stm32f1)                      # hal/ports/stm32f1
set(SERVO_BOARD_STARTUP ${PROJECT_SOURCE_DIR}/hal/ports/stm32f1/startup_stm32f103.c)
