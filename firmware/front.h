/* The front end linked into this build: the serial gateway (MODE=gate) or
 * the I2C slave (MODE=slave). main() only knows this interface. */
#ifndef ORFA_FRONT_H
#define ORFA_FRONT_H

void front_init(void);
/* One step of the front end's work; when it has none, it calls sys_poll()
 * (the link-loss failsafe): the busy path pays nothing for it. */
void front_poll(void);

#endif
