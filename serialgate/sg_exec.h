/*
 * Executes a parsed request and writes its reply line (docs/protocol.md).
 * Hardware is reached only through twi_master.h, regmap.h and sg_out(), so
 * the executor is also compiled and tested on the host with fakes of them.
 */
#ifndef SG_EXEC_H
#define SG_EXEC_H

#include <stdint.h>

#include "serialgate/sg_parse.h"

#define SG_LOCAL_DEFAULT 0xAA
#define SG_KHZ_DEFAULT   100

/* Sends one reply character (provided by the front end or a test). */
void sg_out(uint8_t c);

/* Two reply characters, A first. */
void sg_out2(uint8_t a, uint8_t b);

/* Local address AA, bus clock as for C0064. */
void sg_exec_init(void);

/* Runs the request the parser just completed (or replies its error). */
void sg_exec(sg_parser_t *p);

/* After SG_LOST: ERROR 04 for each request the receive buffer lost,
 * sg_lost_answered() after each. */
void sg_exec_lost(const sg_parser_t *p);

/* A lost request's ERROR 04 is queued (provided by the front end or a
 * test): the gateway feeds the watchdog there. A flood of short requests
 * beyond the flow rule owes thousands of them (up to 65535 a lost run),
 * a loop of seconds; the CPU, not the wire, holds it back while the
 * receive interrupt takes most cycles, so uart_putc() never waits for
 * room, the only place it feeds on progress. Each reply is progress. */
void sg_lost_answered(void);

#endif
