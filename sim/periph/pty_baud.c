/*
 * pty_baud.c: the rate a PC set on the pty. termios2 (TCGETS2) carries the
 * speed as a number, also the rates pyserial sets through BOTHER (14400,
 * 28800, 76800), which tcgetattr/cfgetospeed cannot show. On Linux a
 * termios ioctl on the master reaches the slave's settings, the ones the
 * PC's program changed. Its own file: <asm/termbits.h> and <termios.h>
 * cannot be included together.
 */
#include <sys/ioctl.h>
#include <asm/termbits.h>

#include "periph/pty.h"

unsigned pty_baud(const pty_t *p)
{
	struct termios2 t;

	if (p->master < 0 || ioctl(p->master, TCGETS2, &t) < 0) {
		return 0;
	}
	return t.c_ospeed;
}
