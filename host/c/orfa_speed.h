/*
 * orfa_speed.h: serial rates that termios has no Bxxx name for (14400,
 * 28800, 76800: rates an ORFA gateway can be built for), set as a number of
 * bits per second. Linux takes any rate through termios2 (BOTHER); elsewhere
 * these calls report ENOTSUP. Internal to the library (orfa.c) and its tests.
 */
#ifndef ORFA_SPEED_H
#define ORFA_SPEED_H

/* Set FD's input and output rate to BAUD bits per second, the rest of its
 * settings as they are. 0, or -1 with errno. */
int orfa_speed_set(int fd, long baud);

/* FD's output rate in bits per second, or -1 with errno. */
long orfa_speed_get(int fd);

#endif
