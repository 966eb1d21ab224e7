/* ARM semihosting (bkpt 0xAB) for the QEMU example: the lockstep
   transport's stdin and stderr, and the exit code. */
#ifndef SEMIHOST_H
#define SEMIHOST_H
#include <stddef.h>
#include <stdint.h>

/* Opens ":tt": mode 0 = stdin, 4 = write (stdout), 8 = append (QEMU:
   stderr). -1 on failure. */
int32_t sh_open_tt(uint32_t mode);
/* Reads up to len bytes; returns the bytes read (0 at end of input), -1 on error. */
int32_t sh_read(int32_t fd, uint8_t *buf, uint32_t len);
/* Writes all bytes; 0 on success. */
int32_t sh_write(int32_t fd, const uint8_t *buf, uint32_t len);
/* Ends the QEMU process with this exit code. */
void sh_exit(uint32_t code) __attribute__((noreturn));

#endif
