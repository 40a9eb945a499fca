// STM32F405 USB OTG FS registers (RM0090, "USB on-the-go full-speed"): the
// core global and device-mode registers the device driver uses, their bits,
// and the data FIFO windows. Offsets are from the peripheral base; device
// mode only (no host-mode registers).
//
// The driver (otg_fs_controller.h) reaches the peripheral through an access
// policy with four operations: read(offset), write(offset, value),
// write_fifo_word(fifo, word) and read_fifo_word(). OtgFsMmio below is the
// MCU's: inline volatile accesses at kOtgFsBase + offset, so the per-word
// FIFO loops compile to plain stores and loads (no calls). A test passes a
// fake with the same four operations over a register block in RAM that also
// plays the core's side effects (write-1-to-clear flags, self-clearing reset
// bits, the receive status queue, the FIFO contents).
#ifndef HADYNET_BOARDS_STM32F405_OTG_FS_REGISTERS_H_
#define HADYNET_BOARDS_STM32F405_OTG_FS_REGISTERS_H_

#include <cstdint>

namespace hadynet::board::stm32::otg {

inline constexpr std::uintptr_t kOtgFsBase = 0x50000000;  // AHB2
inline constexpr int kOtgFsIrq = 67;                      // NVIC line of OTG_FS (global interrupt)
inline constexpr int kEndpoints = 4;                      // EP0..EP3, each IN and OUT
inline constexpr std::uint32_t kFifoRamWords = 320;       // 1.25 KiB shared FIFO RAM
inline constexpr std::uint32_t kMinTxFifoWords = 16;      // smallest legal TX FIFO depth

// ---- core global registers (offsets)
inline constexpr std::uint32_t kGotgctl = 0x000;   // OTG control and status
inline constexpr std::uint32_t kGahbcfg = 0x008;   // AHB configuration
inline constexpr std::uint32_t kGusbcfg = 0x00C;   // USB configuration
inline constexpr std::uint32_t kGrstctl = 0x010;   // reset
inline constexpr std::uint32_t kGintsts = 0x014;   // core interrupt status (mostly write 1 to clear)
inline constexpr std::uint32_t kGintmsk = 0x018;   // core interrupt mask
inline constexpr std::uint32_t kGrxstsr = 0x01C;   // receive status, read (peek)
inline constexpr std::uint32_t kGrxstsp = 0x020;   // receive status, read and pop
inline constexpr std::uint32_t kGrxfsiz = 0x024;   // RX FIFO depth (words)
inline constexpr std::uint32_t kDieptxf0 = 0x028;  // EP0 TX FIFO start and depth (GNPTXFSIZ in host mode)
inline constexpr std::uint32_t kGccfg = 0x038;     // general core configuration: PHY power, VBUS sensing
inline constexpr std::uint32_t kCid = 0x03C;       // core ID (user data)
// TX FIFO of IN endpoint n = 1..3: start (bits 15:0) and depth (31:16), words.
constexpr std::uint32_t dieptxf(int n) noexcept { return 0x104 + 4u * static_cast<std::uint32_t>(n - 1); }

// ---- device registers
inline constexpr std::uint32_t kDcfg = 0x800;        // device configuration: speed, address
inline constexpr std::uint32_t kDctl = 0x804;        // device control: soft disconnect, global NAKs
inline constexpr std::uint32_t kDsts = 0x808;        // device status: enumerated speed, suspend
inline constexpr std::uint32_t kDiepmsk = 0x810;     // IN endpoint common interrupt mask
inline constexpr std::uint32_t kDoepmsk = 0x814;     // OUT endpoint common interrupt mask
inline constexpr std::uint32_t kDaint = 0x818;       // all endpoints interrupt: IN bits 15:0, OUT 31:16
inline constexpr std::uint32_t kDaintmsk = 0x81C;    // its mask
inline constexpr std::uint32_t kDiepempmsk = 0x834;  // IN endpoint TX FIFO empty interrupt mask, bit n
inline constexpr std::uint32_t kPcgcctl = 0xE00;     // power and clock gating

// ---- per-endpoint registers, n = 0..3
constexpr std::uint32_t diepctl(int n) noexcept { return 0x900 + 0x20u * static_cast<std::uint32_t>(n); }
constexpr std::uint32_t diepint(int n) noexcept { return 0x908 + 0x20u * static_cast<std::uint32_t>(n); }
constexpr std::uint32_t dieptsiz(int n) noexcept { return 0x910 + 0x20u * static_cast<std::uint32_t>(n); }
constexpr std::uint32_t dtxfsts(int n) noexcept { return 0x918 + 0x20u * static_cast<std::uint32_t>(n); }
constexpr std::uint32_t doepctl(int n) noexcept { return 0xB00 + 0x20u * static_cast<std::uint32_t>(n); }
constexpr std::uint32_t doepint(int n) noexcept { return 0xB08 + 0x20u * static_cast<std::uint32_t>(n); }
constexpr std::uint32_t doeptsiz(int n) noexcept { return 0xB10 + 0x20u * static_cast<std::uint32_t>(n); }
// Data FIFO window n (4 KiB): writing pushes to TX FIFO n, reading (any
// window) pops the shared RX FIFO.
constexpr std::uint32_t fifo_window(int n) noexcept { return 0x1000u * static_cast<std::uint32_t>(n + 1); }

// ---- GAHBCFG
inline constexpr std::uint32_t kGahbcfgGlobalInterrupt = 1u << 0;  // GINTMSK: the core's interrupt line on
inline constexpr std::uint32_t kGahbcfgTxEmptyLevel = 1u << 7;     // TXFELVL: TXFE when the TX FIFO is completely empty

// ---- GUSBCFG
inline constexpr std::uint32_t kGusbcfgPhySelect = 1u << 6;  // PHYSEL: full-speed embedded PHY
inline constexpr int kGusbcfgTurnaround = 10;                // TRDT, bits 13:10, in PHY clocks
inline constexpr std::uint32_t kGusbcfgTurnaroundMask = 0xFu << 10;
inline constexpr std::uint32_t kGusbcfgForceHost = 1u << 29;    // FHMOD
inline constexpr std::uint32_t kGusbcfgForceDevice = 1u << 30;  // FDMOD

// ---- GRSTCTL
inline constexpr std::uint32_t kGrstctlCoreReset = 1u << 0;  // CSRST, self-clearing
inline constexpr std::uint32_t kGrstctlRxFlush = 1u << 4;    // RXFFLSH, self-clearing
inline constexpr std::uint32_t kGrstctlTxFlush = 1u << 5;    // TXFFLSH, self-clearing
inline constexpr int kGrstctlTxFifoNumber = 6;               // TXFNUM, bits 10:6: which TX FIFO to flush
inline constexpr std::uint32_t kGrstctlTxFlushAll = 0x10;    // TXFNUM value: every TX FIFO
inline constexpr std::uint32_t kGrstctlAhbIdle = 1u << 31;   // AHBIDL

// ---- GINTSTS / GINTMSK
inline constexpr std::uint32_t kGintCurrentModeHost = 1u << 0;        // CMOD (GINTSTS only): 0 device, 1 host
inline constexpr std::uint32_t kGintModeMismatch = 1u << 1;           // MMIS
inline constexpr std::uint32_t kGintOtg = 1u << 2;                    // OTGINT
inline constexpr std::uint32_t kGintSof = 1u << 3;                    // SOF
inline constexpr std::uint32_t kGintRxFifoNonEmpty = 1u << 4;         // RXFLVL (read only: pop GRXSTSP)
inline constexpr std::uint32_t kGintGlobalOutNakEffective = 1u << 7;  // GONAKEFF (read only)
inline constexpr std::uint32_t kGintEarlySuspend = 1u << 10;          // ESUSP
inline constexpr std::uint32_t kGintSuspend = 1u << 11;               // USBSUSP
inline constexpr std::uint32_t kGintBusReset = 1u << 12;              // USBRST
inline constexpr std::uint32_t kGintEnumerationDone = 1u << 13;       // ENUMDNE
inline constexpr std::uint32_t kGintInEndpoint = 1u << 18;            // IEPINT (read only: see DAINT)
inline constexpr std::uint32_t kGintOutEndpoint = 1u << 19;           // OEPINT (read only: see DAINT)
inline constexpr std::uint32_t kGintWakeup = 1u << 31;                // WKUPINT: resume detected

// ---- GRXSTSR / GRXSTSP (device mode)
inline constexpr std::uint32_t kRxStatusEndpointMask = 0xFu;  // EPNUM, bits 3:0
inline constexpr int kRxStatusByteCount = 4;                  // BCNT, bits 14:4
inline constexpr std::uint32_t kRxStatusByteCountMask = 0x7FFu << 4;
inline constexpr int kRxStatusPacketStatus = 17;  // PKTSTS, bits 20:17
inline constexpr std::uint32_t kRxStatusPacketStatusMask = 0xFu << 17;
// PKTSTS values
inline constexpr std::uint32_t kRxGlobalOutNak = 1;   // global OUT NAK effective
inline constexpr std::uint32_t kRxOutData = 2;        // OUT data packet received (BCNT bytes follow)
inline constexpr std::uint32_t kRxOutComplete = 3;    // OUT transfer completed (no data)
inline constexpr std::uint32_t kRxSetupComplete = 4;  // SETUP stage done (no data); popping it raises STUP
inline constexpr std::uint32_t kRxSetupData = 6;      // SETUP data packet received (8 bytes follow)

// ---- GRXFSIZ, DIEPTXF0, DIEPTXFn: start address (15:0) and depth (31:16), words
inline constexpr int kTxFifoDepth = 16;

// ---- GCCFG
inline constexpr std::uint32_t kGccfgPhyPowerUp = 1u << 16;     // PWRDWN: 1 = transceiver active
inline constexpr std::uint32_t kGccfgVbusSenseA = 1u << 18;     // VBUSASEN (A-device, host)
inline constexpr std::uint32_t kGccfgVbusSenseB = 1u << 19;     // VBUSBSEN: sense VBUS on PA9 as B-device
inline constexpr std::uint32_t kGccfgNoVbusSensing = 1u << 21;  // NOVBUSSENS: VBUS assumed present

// ---- DCFG
inline constexpr std::uint32_t kDcfgSpeedMask = 3u << 0;           // DSPD
inline constexpr std::uint32_t kDcfgSpeedFull = 3u << 0;           // full speed, embedded PHY (48 MHz)
inline constexpr std::uint32_t kDcfgNonZeroLengthStall = 1u << 2;  // NZLSOHSK (not used: 0 = ACK and deliver)
inline constexpr int kDcfgAddress = 4;                             // DAD, bits 10:4
inline constexpr std::uint32_t kDcfgAddressMask = 0x7Fu << 4;

// ---- DCTL
inline constexpr std::uint32_t kDctlSoftDisconnect = 1u << 1;      // SDIS: D+ pull-up off
inline constexpr std::uint32_t kDctlSetGlobalOutNak = 1u << 9;     // SGONAK
inline constexpr std::uint32_t kDctlClearGlobalOutNak = 1u << 10;  // CGONAK
inline constexpr std::uint32_t kDctlClearGlobalInNak = 1u << 8;    // CGINAK

// ---- DSTS
inline constexpr std::uint32_t kDstsSuspended = 1u << 0;    // SUSPSTS
inline constexpr std::uint32_t kDstsSpeedMask = 3u << 1;    // ENUMSPD
inline constexpr std::uint32_t kDstsSpeedFull48 = 3u << 1;  // full speed, 48 MHz PHY clock

// ---- DIEPMSK / DIEPINTn
inline constexpr std::uint32_t kInTransferComplete = 1u << 0;  // XFRC (write 1 to clear)
inline constexpr std::uint32_t kInDisabled = 1u << 1;          // EPDISD (write 1 to clear)
inline constexpr std::uint32_t kInTimeout = 1u << 3;           // TOC (write 1 to clear)
inline constexpr std::uint32_t kInTxFifoEmpty = 1u << 7;       // TXFE (read only; masked by DIEPEMPMSK)

// ---- DOEPMSK / DOEPINTn
inline constexpr std::uint32_t kOutTransferComplete = 1u << 0;    // XFRC
inline constexpr std::uint32_t kOutDisabled = 1u << 1;            // EPDISD
inline constexpr std::uint32_t kOutSetupDone = 1u << 3;           // STUP: SETUP stage done (EP0)
inline constexpr std::uint32_t kOutTokenWhileDisabled = 1u << 4;  // OTEPDIS
inline constexpr std::uint32_t kOutBackToBackSetup = 1u << 6;     // B2BSTUP

// ---- DAINT / DAINTMSK
constexpr std::uint32_t daint_in(int n) noexcept { return 1u << n; }
constexpr std::uint32_t daint_out(int n) noexcept { return 1u << (16 + n); }

// ---- DIEPCTLn / DOEPCTLn
inline constexpr std::uint32_t kEpctlMaxPacketMask = 0x7FFu;  // MPSIZ, bytes (EP1..3)
inline constexpr std::uint32_t kEpctl0MaxPacket64 = 0u;       // MPSIZ of EP0 (bits 1:0): 0 = 64 bytes
inline constexpr std::uint32_t kEpctl0MaxPacketMask = 3u;
inline constexpr std::uint32_t kEpctlActive = 1u << 15;     // USBAEP
inline constexpr std::uint32_t kEpctlNakStatus = 1u << 17;  // NAKSTS (read only)
inline constexpr int kEpctlType = 18;                       // EPTYP, bits 19:18
inline constexpr std::uint32_t kEpctlTypeMask = 3u << 18;
inline constexpr std::uint32_t kEpctlStall = 1u << 21;  // STALL
inline constexpr int kEpctlTxFifo = 22;                 // TXFNUM, bits 25:22 (IN only)
inline constexpr std::uint32_t kEpctlTxFifoMask = 0xFu << 22;
inline constexpr std::uint32_t kEpctlClearNak = 1u << 26;  // CNAK
inline constexpr std::uint32_t kEpctlSetNak = 1u << 27;    // SNAK
inline constexpr std::uint32_t kEpctlSetData0 = 1u << 28;  // SD0PID: next data PID DATA0
inline constexpr std::uint32_t kEpctlDisable = 1u << 30;   // EPDIS
inline constexpr std::uint32_t kEpctlEnable = 1u << 31;    // EPENA (cleared by the core at completion)

// ---- DIEPTSIZn / DOEPTSIZn
inline constexpr int kTsizPacketCount = 19;                   // PKTCNT, from bit 19
inline constexpr std::uint32_t kTsizSizeMask = 0x7FFFFu;      // XFRSIZ, bytes (EP1..3: 19 bits)
inline constexpr std::uint32_t kTsizPacketCountMax = 0x3FFu;  // PKTCNT (EP1..3: 10 bits)
inline constexpr std::uint32_t kTsiz0SizeMask = 0x7Fu;        // XFRSIZ of EP0 (7 bits)
inline constexpr int kTsizSetupCount = 29;                    // STUPCNT (DOEPTSIZ0), bits 30:29
inline constexpr std::uint32_t kTsizSetupCountMask = 3u << 29;

// ---- DTXFSTSn
inline constexpr std::uint32_t kDtxfstsSpaceMask = 0xFFFFu;  // INEPTFSAV: free words in TX FIFO n

// ---- RCC and GPIO bits the board hook uses (base addresses: stm32f405_registers.h)
inline constexpr std::uintptr_t kRccAhb2Enr = 0x40023800 + 0x34;  // AHB2 clocks
inline constexpr std::uint32_t kRccAhb2EnrOtgFs = 1u << 7;        // OTGFSEN
inline constexpr std::uint32_t kGpioAfOtgFs = 10;                 // AF10: OTG_FS on PA11 (DM), PA12 (DP)
inline constexpr std::uintptr_t kGpioOspeedr = 0x08;              // output speed, 2 bits per pin (3: very high)

// The MCU access policy: the real peripheral.
struct OtgFsMmio {
  static volatile std::uint32_t& at(std::uint32_t offset) noexcept {
    return *reinterpret_cast<volatile std::uint32_t*>(kOtgFsBase + offset);
  }
  std::uint32_t read(std::uint32_t offset) const noexcept { return at(offset); }
  void write(std::uint32_t offset, std::uint32_t value) const noexcept { at(offset) = value; }
  // One 32-bit word into TX FIFO `fifo` (0..3).
  void write_fifo_word(int fifo, std::uint32_t word) const noexcept { at(fifo_window(fifo)) = word; }
  // One 32-bit word from the RX FIFO.
  std::uint32_t read_fifo_word() const noexcept { return at(fifo_window(0)); }
};

}  // namespace hadynet::board::stm32::otg

#endif  // HADYNET_BOARDS_STM32F405_OTG_FS_REGISTERS_H_
