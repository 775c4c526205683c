"""servoctl: the PC side of the open servo firmware."""
