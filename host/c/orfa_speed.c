/*
 * Rates by number (orfa_speed.h). Its own file: <asm/termbits.h>, which has
 * termios2, cannot be included beside <termios.h>.
 */
#include "orfa_speed.h"

#include <errno.h>

#if defined(__linux__)
#include <asm/termbits.h>
#include <sys/ioctl.h>

int orfa_speed_set(int fd, long baud)
{
	struct termios2 t;

	if (baud <= 0 || ioctl(fd, TCGETS2, &t) < 0) {
		if (baud <= 0) {
			errno = EINVAL;
		}
		return -1;
	}
	t.c_cflag &= ~(tcflag_t)CBAUD;
	t.c_cflag |= BOTHER;
	t.c_cflag &= ~(tcflag_t)(CBAUD << IBSHIFT);     /* input rate: the same number */
	t.c_cflag |= BOTHER << IBSHIFT;
	t.c_ispeed = (speed_t)baud;
	t.c_ospeed = (speed_t)baud;
	return ioctl(fd, TCSETS2, &t);
}

long orfa_speed_get(int fd)
{
	struct termios2 t;

	if (ioctl(fd, TCGETS2, &t) < 0) {
		return -1;
	}
	return (long)t.c_ospeed;
}

#else

int orfa_speed_set(int fd, long baud)
{
	(void)fd;
	(void)baud;
	errno = ENOTSUP;
	return -1;
}

long orfa_speed_get(int fd)
{
	(void)fd;
	errno = ENOTSUP;
	return -1;
}

#endif
