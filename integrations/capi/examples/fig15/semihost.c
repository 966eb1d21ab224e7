#include "semihost.h"

enum { SYS_OPEN = 0x01, SYS_WRITE = 0x05, SYS_READ = 0x06, SYS_EXIT_EXTENDED = 0x20 };
enum { ADP_STOPPED_APPLICATION_EXIT = 0x20026 };

static int32_t call(uint32_t op, const void *args)
{
    register uint32_t r0 __asm__("r0") = op;
    register const void *r1 __asm__("r1") = args;
    __asm__ volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
    return (int32_t)r0;
}

int32_t sh_open_tt(uint32_t mode)
{
    static const char name[] = ":tt";
    const uint32_t args[3] = {(uint32_t)name, mode, sizeof name - 1};
    return call(SYS_OPEN, args);
}

int32_t sh_read(int32_t fd, uint8_t *buf, uint32_t len)
{
    const uint32_t args[3] = {(uint32_t)fd, (uint32_t)buf, len};
    int32_t left = call(SYS_READ, args); /* bytes NOT read */
    if (left < 0 || (uint32_t)left > len) {
        return -1;
    }
    return (int32_t)(len - (uint32_t)left);
}

int32_t sh_write(int32_t fd, const uint8_t *buf, uint32_t len)
{
    const uint32_t args[3] = {(uint32_t)fd, (uint32_t)buf, len};
    return call(SYS_WRITE, args); /* bytes NOT written */
}

void sh_exit(uint32_t code)
{
    const uint32_t args[2] = {ADP_STOPPED_APPLICATION_EXIT, code};
    call(SYS_EXIT_EXTENDED, args);
    for (;;) {
    }
}
