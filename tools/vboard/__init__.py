"""Virtual boards: the shipped firmware images, unchanged, on an emulated
STM32F103 or STM32F030 (Unicorn's Cortex-M3/M0 and peripheral models laid
out from ST's SVD files), wired to the simulator's motor. README.md,
"Virtual boards"."""
