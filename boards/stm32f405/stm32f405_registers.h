// STM32F405 peripheral registers this board uses (reference manual RM0090):
// addresses and the bits we set, nothing else.
#ifndef HADYNET_BOARDS_STM32F405_STM32F405_REGISTERS_H_
#define HADYNET_BOARDS_STM32F405_STM32F405_REGISTERS_H_

#include <cstdint>

namespace hadynet::board::stm32 {

// ---- RCC: reset and clock control
inline constexpr std::uintptr_t kRcc = 0x40023800;
inline constexpr std::uintptr_t kRccCr = kRcc + 0x00;       // oscillators and PLL on/ready
inline constexpr std::uintptr_t kRccPllCfgr = kRcc + 0x04;  // main PLL M, N, P, Q, source
inline constexpr std::uintptr_t kRccCfgr = kRcc + 0x08;     // clock switch, bus prescalers
inline constexpr std::uintptr_t kRccAhb1Enr = kRcc + 0x30;  // AHB1 clocks: GPIO, DMA
inline constexpr std::uintptr_t kRccApb1Enr = kRcc + 0x40;  // APB1 clocks: PWR
inline constexpr std::uintptr_t kRccApb2Enr = kRcc + 0x44;  // APB2 clocks: USART1, ADC1
inline constexpr std::uint32_t kRccCrHsiRdy = 1u << 1;
inline constexpr std::uint32_t kRccCrHseOn = 1u << 16;
inline constexpr std::uint32_t kRccCrHseRdy = 1u << 17;
inline constexpr std::uint32_t kRccCrPllOn = 1u << 24;
inline constexpr std::uint32_t kRccCrPllRdy = 1u << 25;
inline constexpr std::uint32_t kRccPllCfgrSrcHse = 1u << 22;
inline constexpr int kRccPllCfgrM = 0;   // bits 5:0, VCO input = source / M
inline constexpr int kRccPllCfgrN = 6;   // bits 14:6, VCO = input * N
inline constexpr int kRccPllCfgrP = 16;  // bits 17:16, SYSCLK = VCO / (2 (P+1)): 0 -> /2
inline constexpr int kRccPllCfgrQ = 24;  // bits 27:24, USB/SDIO clock = VCO / Q
inline constexpr std::uint32_t kRccCfgrSwMask = 3u << 0;
inline constexpr std::uint32_t kRccCfgrSwPll = 2u << 0;
inline constexpr std::uint32_t kRccCfgrSwsMask = 3u << 2;
inline constexpr std::uint32_t kRccCfgrSwsPll = 2u << 2;
inline constexpr int kRccCfgrHpre = 4;    // bits 7:4, AHB prescaler (0: /1)
inline constexpr int kRccCfgrPpre1 = 10;  // bits 12:10, APB1 prescaler (5: /4)
inline constexpr int kRccCfgrPpre2 = 13;  // bits 15:13, APB2 prescaler (4: /2)
inline constexpr std::uint32_t kRccAhb1EnrGpioA = 1u << 0;
inline constexpr std::uint32_t kRccAhb1EnrGpioB = 1u << 1;
inline constexpr std::uint32_t kRccAhb1EnrDma2 = 1u << 22;
inline constexpr std::uint32_t kRccApb1EnrPwr = 1u << 28;
inline constexpr std::uint32_t kRccApb2EnrUsart1 = 1u << 4;
inline constexpr std::uint32_t kRccApb2EnrAdc1 = 1u << 8;

// ---- PWR: voltage scaling (scale 1 needed above 144 MHz)
inline constexpr std::uintptr_t kPwrCr = 0x40007000;
inline constexpr std::uint32_t kPwrCrVosScale1 = 1u << 14;

// ---- Flash interface: wait states and caches
inline constexpr std::uintptr_t kFlashAcr = 0x40023C00;
inline constexpr std::uint32_t kFlashAcrLatencyMask = 7u << 0;
inline constexpr std::uint32_t kFlashAcrPrefetch = 1u << 8;
inline constexpr std::uint32_t kFlashAcrICache = 1u << 9;
inline constexpr std::uint32_t kFlashAcrDCache = 1u << 10;

// ---- GPIO (mode register: 2 bits per pin; 0 input, 2 alternate, 3 analog)
inline constexpr std::uintptr_t kGpioA = 0x40020000;
inline constexpr std::uintptr_t kGpioB = 0x40020400;
inline constexpr std::uintptr_t kGpioModer = 0x00;
inline constexpr std::uintptr_t kGpioAfrh = 0x24;  // alternate function of pins 8..15, 4 bits each
inline constexpr std::uint32_t kGpioModeAlternate = 2;
inline constexpr std::uint32_t kGpioModeAnalog = 3;

// ---- USART1 (APB2)
inline constexpr std::uintptr_t kUsart1 = 0x40011000;
inline constexpr std::uintptr_t kUsartSr = kUsart1 + 0x00;   // status
inline constexpr std::uintptr_t kUsartDr = kUsart1 + 0x04;   // data
inline constexpr std::uintptr_t kUsartBrr = kUsart1 + 0x08;  // baud rate: f_APB2 / baud (oversampling 16)
inline constexpr std::uintptr_t kUsartCr1 = kUsart1 + 0x0C;  // enables
inline constexpr std::uint32_t kUsartSrOverrun = 1u << 3;
inline constexpr std::uint32_t kUsartSrRxNotEmpty = 1u << 5;
inline constexpr std::uint32_t kUsartSrTxEmpty = 1u << 7;
inline constexpr std::uint32_t kUsartCr1RxEnable = 1u << 2;
inline constexpr std::uint32_t kUsartCr1TxEnable = 1u << 3;
inline constexpr std::uint32_t kUsartCr1RxInterrupt = 1u << 5;
inline constexpr std::uint32_t kUsartCr1Enable = 1u << 13;
inline constexpr int kUsart1Irq = 37;  // NVIC line

// ---- ADC1 (APB2) and the ADC common registers
inline constexpr std::uintptr_t kAdc1 = 0x40012000;
inline constexpr std::uintptr_t kAdcCr1 = kAdc1 + 0x04;
inline constexpr std::uintptr_t kAdcCr2 = kAdc1 + 0x08;
inline constexpr std::uintptr_t kAdcSmpr1 = kAdc1 + 0x0C;  // sample time, channels 10..18 (3 bits each)
inline constexpr std::uintptr_t kAdcSmpr2 = kAdc1 + 0x10;  // sample time, channels 0..9
inline constexpr std::uintptr_t kAdcSqr1 = kAdc1 + 0x2C;   // sequence length (L, bits 23:20) and SQ13..16
inline constexpr std::uintptr_t kAdcSqr2 = kAdc1 + 0x30;   // SQ7..12 (5 bits each)
inline constexpr std::uintptr_t kAdcSqr3 = kAdc1 + 0x34;   // SQ1..6
inline constexpr std::uintptr_t kAdcDr = kAdc1 + 0x4C;     // regular data
inline constexpr std::uintptr_t kAdcCcr = 0x40012300 + 0x04;  // common control: ADC clock prescaler
inline constexpr std::uint32_t kAdcCr1Scan = 1u << 8;
inline constexpr std::uint32_t kAdcCr2AdOn = 1u << 0;
inline constexpr std::uint32_t kAdcCr2Continuous = 1u << 1;
inline constexpr std::uint32_t kAdcCr2Dma = 1u << 8;
inline constexpr std::uint32_t kAdcCr2DmaContinue = 1u << 9;  // DDS: keep requesting DMA (circular)
inline constexpr std::uint32_t kAdcCr2SwStart = 1u << 30;
inline constexpr int kAdcCcrPrescaler = 16;  // bits 17:16: 1 -> PCLK2 / 4
inline constexpr int kAdcSqrLength = 20;     // SQR1 bits 23:20: conversions - 1

// ---- DMA2 stream 0, channel 0 = ADC1
inline constexpr std::uintptr_t kDma2 = 0x40026400;
inline constexpr std::uintptr_t kDma2S0Cr = kDma2 + 0x10;    // stream configuration
inline constexpr std::uintptr_t kDma2S0Ndtr = kDma2 + 0x14;  // items to transfer
inline constexpr std::uintptr_t kDma2S0Par = kDma2 + 0x18;   // peripheral address
inline constexpr std::uintptr_t kDma2S0M0ar = kDma2 + 0x1C;  // memory address
inline constexpr std::uint32_t kDmaCrEnable = 1u << 0;
inline constexpr std::uint32_t kDmaCrCircular = 1u << 8;
inline constexpr std::uint32_t kDmaCrMemIncrement = 1u << 10;
inline constexpr std::uint32_t kDmaCrPeriph16 = 1u << 11;  // PSIZE = half-word
inline constexpr std::uint32_t kDmaCrMem16 = 1u << 13;     // MSIZE = half-word
inline constexpr std::uint32_t kDmaCrPriorityHigh = 2u << 16;
inline constexpr int kDmaCrChannel = 25;  // CHSEL bits 27:25; DIR 0 = peripheral to memory

}  // namespace hadynet::board::stm32

#endif  // HADYNET_BOARDS_STM32F405_STM32F405_REGISTERS_H_
