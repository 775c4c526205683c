# The simulator: the firmware core on simulated servos (host only). Its
# update images are never executed: the slot's bytes stand for the code.
set(SERVO_BOARD_ID 0x5100)                                 # the update image header's board
