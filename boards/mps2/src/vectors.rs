//! Device interrupt vectors of the QEMU `mps2` images, included by each of
//! them (the STM32F411's come with its PAC). cortex-m-rt's default table holds 240 entries (960 bytes of flash);
//! these images unmask only UART0 RX (IRQ 0) and timer 0 (IRQ 8), so the table
//! stops after IRQ 31. Every entry is `DefaultHandler`, which the boards dispatch
//! by the active IRQ number. An IRQ above 31 is never unmasked here.

unsafe extern "C" {
    fn DefaultHandler();
}

/// IRQ 0..31 → `DefaultHandler` (cortex-m-rt places it at `ORIGIN(FLASH) + 0x40`).
#[unsafe(link_section = ".vector_table.interrupts")]
#[unsafe(no_mangle)]
pub static __INTERRUPTS: [unsafe extern "C" fn(); 32] = [DefaultHandler; 32];
