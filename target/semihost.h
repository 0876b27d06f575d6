/*
 * semihost.h - the few Arm semihosting calls the image needs: write a
 * string or a character to the host console, and exit with a status.
 * No newlib rdimon: its printf pulls in malloc.
 */
#ifndef TARGET_SEMIHOST_H
#define TARGET_SEMIHOST_H

/* Write a NUL-terminated string to the host console (SYS_WRITE0). */
void sh_write0(const char *s);

/* Write one character (SYS_WRITEC). */
void sh_writec(char c);

/* End the emulation with this exit status (SYS_EXIT_EXTENDED, reason
 * ADP_Stopped_ApplicationExit): QEMU exits with it. */
__attribute__((noreturn)) void sh_exit(int status);

#endif /* TARGET_SEMIHOST_H */
