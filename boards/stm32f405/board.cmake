# stm32f405: STM32F405RG/VG/ZG (1 MiB flash, 128 KiB SRAM + 64 KiB CCM RAM,
# 168 MHz from an 8 MHz crystal). QEMU's `netduinoplus2` machine runs its
# USART1. The one place for this board's memory sizes and clock:
# boards/CMakeLists.txt generates the linker script's MEMORY (memory.ld) and
# board_config.h from it; clock_tree.h checks its PLL settings against
# BOARD_CORE_CLOCK_HZ at compile time.
set(BOARD_NAME "stm32f405")
set(BOARD_QEMU_MACHINE "netduinoplus2")
set(BOARD_CORE_CLOCK_HZ 168000000)
# External interrupts of the STM32F405 (NVIC lines 0..81).
set(BOARD_IRQ_COUNT 82)
# Memory regions: "NAME ORIGIN BYTES ATTRIBUTES KIND", KIND flash or ram.
#   FLASH at 0x08000000 (aliased at 0 when booting from flash): the
#     firmware's sectors 0..7 (512 KiB) only; sectors 8..11 hold the model
#     slots (firmware/flash/stm32f405_flash_layout.h), so an image that
#     grows into them fails to link instead of being overwritten by a model;
#   SRAM (SRAM1 112 KiB + SRAM2 16 KiB, contiguous): data, bss (with the DMA
#     buffer), then the stack;
#   CCM (core-coupled, no DMA access): nothing yet. QEMU 7.2's netduinoplus2
#     maps 192 KiB of SRAM at 0x20000000 and no CCM, so an image that used
#     the CCM would fault there.
set(BOARD_MEMORY
  "FLASH 0x08000000 524288 rx flash"
  "SRAM 0x20000000 131072 rwx ram"
  "CCM 0x10000000 65536 rw ram")
set(BOARD_REGION_TEXT FLASH)
set(BOARD_REGION_DATA SRAM)
set(BOARD_REGION_STACK SRAM)
# Loadcell channels the board scans (board::read_loadcells; the hand's
# tendon loadcells fc0..fc8, board_config.h kLoadcells).
set(BOARD_LOADCELLS 9)
set(BOARD_STACK_BYTES 32768)
set(BOARD_SOURCES board.cc clock_tree.cc loadcells.cc model_flash.cc
  # The USB device port (boards/board_usb.h): OTG FS driver, embedded flash
  # behind the DFU model slots, DFU_DETACH into the ROM bootloader.
  usb_port.cc otg_fs_controller.cc flash_controller.cc system_bootloader.cc)
# The firmware image carries the USB device (firmware/app/usb_link.cc).
set(BOARD_HAS_USB TRUE)
