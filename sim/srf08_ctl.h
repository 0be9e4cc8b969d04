/*
 * srf08_ctl.h: the control request `srf08` (docs/simulator.md), kept out of
 * control.c so that file only dispatches to it.
 */
#ifndef SIM_SRF08_CTL_H
#define SIM_SRF08_CTL_H

#include <stddef.h>
#include <stdint.h>

#include "parts/srf08.h"

/* Answer `srf08 ADDR range MM [MM2]`, `srf08 ADDR light N` or `srf08 ADDR`
 * (ARGV[0] is "srf08") for the N devices at DEVS; NOW is the current cycle.
 * Writes one reply line (no newline) into OUT: "OK", the state, or "ERR ...". */
void srf08_control(srf08_t *devs, int n, uint64_t now, int argc, char **argv,
		   char *out, size_t cap);

#endif
