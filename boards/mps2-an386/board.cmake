# mps2-an386: Arm MPS2(+) with the AN386 FPGA image, a Cortex-M4F with the
# CMSDK peripherals; CI runs it under QEMU (`-M mps2-an386`). The one place
# for this board's memory sizes and clock: boards/CMakeLists.txt generates
# the linker script's MEMORY (memory.ld) and board_config.h from it.
set(BOARD_NAME "mps2-an386")
set(BOARD_QEMU_MACHINE "mps2-an386")
# SYSCLK drives the core, SysTick (processor clock) and the APB peripherals.
set(BOARD_CORE_CLOCK_HZ 25000000)
# External interrupts of the AN386 image (NVIC lines 0..31).
set(BOARD_IRQ_COUNT 32)
# Memory regions: "NAME ORIGIN BYTES ATTRIBUTES KIND", KIND flash or ram.
#   ZBT SSRAM1 (4 MiB at 0): code and constants (QEMU loads the ELF there);
#   ZBT SSRAM2/3 (4 MiB at 0x20000000): data, bss, stack.
# (16 MiB of PSRAM at 0x21000000 is not used.)
set(BOARD_MEMORY
  "FLASH 0x00000000 4194304 rx flash"
  "RAM 0x20000000 4194304 rwx ram")
set(BOARD_REGION_TEXT FLASH)
set(BOARD_REGION_DATA RAM)
set(BOARD_REGION_STACK RAM)
# Loadcell channels the board scans (board::read_loadcells; the hand's
# tendon loadcells fc0..fc8, board_config.h kLoadcells).
set(BOARD_LOADCELLS 9)
set(BOARD_STACK_BYTES 65536)
set(BOARD_SOURCES board.cc)
