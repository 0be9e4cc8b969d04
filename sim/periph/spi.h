/*
 * spi.h: the simulator's own SPI master model, replacing simavr 1.6's
 * (every byte 743 cycles whatever SPR/SPI2X say, no modes; see
 * docs/simulator.md, "What simavr 1.6 gets wrong"), and the bus of virtual SPI
 * devices behind it.
 *
 * Registers SPCR/SPSR/SPDR are taken over after avr_init. Master mode:
 * a write to SPDR starts a byte; it takes 8 SCK periods, SCK period =
 * 4/16/64/128 cycles by SPR1:0, halved by SPI2X; then SPIF is set (and the
 * SPI_STC interrupt requested while SPIE). SPIF and WCOL clear by reading
 * SPSR with them set and then accessing SPDR, SPIF also on entering the
 * ISR. A write to SPDR while a byte is on the wire sets WCOL and is lost.
 * Slave mode (MSTR=0), SS mode fault and the double-buffered receive are
 * not modelled: in slave mode SPDR writes just load the register.
 *
 * The byte is computed edge by edge: the 16 SCK edges of the master's
 * CPOL/CPHA/DORD; each selected device reacts to the physical edges in
 * the mode it declares (sampling MOSI on its sampling edge, changing MISO
 * on its shift edge, assembling bytes in its own bit order), so a device
 * spoken to in the wrong mode or bit order misreads and answers as a real
 * one would. MISO reads 1 when no device drives it.
 */
#ifndef SIM_SPI_H
#define SIM_SPI_H

#include <stdint.h>

#include "sim_avr.h"
#include "sim_io.h"
#include "sim_interrupts.h"

#include "harness/signals.h"
#include "harness/trace.h"

#define SPI_MAX_DEVICES 8
#define SPI_LOG 4096

struct spi_t;

typedef struct spi_dev_t {
	const char *kind;		/* "eeprom25", "mcp3008" */
	int mode;			/* SPI mode 0..3 the device speaks */
	int lsb_first;			/* its bit order */
	signal_t *cs;			/* chip select pin, active low */
	struct spi_t *bus;		/* the bus it is on (spi_attach) */
	int selected;
	int out;			/* the MISO level it drives */
	uint32_t txn;			/* counts selections */

	/* Bit level, called by the bus: */
	void (*select)(struct spi_dev_t *d, uint64_t cycle);	/* CS fell */
	void (*deselect)(struct spi_dev_t *d, uint64_t cycle);	/* CS rose */
	void (*in_bit)(struct spi_dev_t *d, int bit, uint64_t cycle);	/* sampling edge */
	int (*next_out)(struct spi_dev_t *d);	/* shift edge: the next MISO bit */
	/* Text for the control interface's `spidev` (memory dump); may be NULL. */
	int (*dump)(struct spi_dev_t *d, char *buf, int size);

	/* Byte-level devices set byte() and use spi_dev_byte_init(): */
	uint8_t (*byte)(struct spi_dev_t *d, uint8_t rx, uint64_t cycle);	/* -> next tx byte */
	void (*reset_state)(struct spi_dev_t *d, uint64_t cycle);	/* at select */
	void (*end)(struct spi_dev_t *d, uint64_t cycle);	/* at deselect */
	uint8_t rx, tx, tx_next;
	int rx_n, tx_n;
} spi_dev_t;

/* Fill D's bit-level callbacks for a device that works in whole bytes. */
void spi_dev_byte_init(spi_dev_t *d);

typedef struct spi_log_t {
	uint64_t cycle;
	const char *cs;			/* pin name or "-" */
	uint32_t txn;
	uint8_t mosi, miso;
} spi_log_t;

/* The board model shows the bus on the pins: PIN 0 = SCK, 1 = MOSI (the
 * master's), 2 = MISO (the selected device's level; 1, nobody driving,
 * while the master is on); ACTIVE 0 gives the pin back to PORT. */
enum { SPI_PIN_SCK, SPI_PIN_MOSI, SPI_PIN_MISO, SPI_PINS };

typedef void (*spi_drive_t)(void *param, int pin, int active, int level, uint64_t cycle);

typedef struct spi_t {
	avr_io_t io;			/* first: reset hook */
	avr_t *avr;
	uint16_t spcr, spsr, spdr;	/* data addresses */
	avr_int_vector_t vect;
	trace_t *trace;
	spi_drive_t drive;
	void *drive_param;

	uint8_t spsr_v;			/* SPIF, WCOL, SPI2X */
	uint8_t rx;			/* what SPDR reads */
	int clear_armed;		/* SPSR was read with SPIF/WCOL set */
	int busy;
	uint8_t tx;			/* byte on the wire */
	uint64_t t0, t_end;
	uint8_t pending_rx;
	const char *pending_cs;
	uint32_t pending_txn;
	int mosi_level;
	int miso_level;			/* what the MISO pin shows */
	/* SCK/MOSI/MISO edges of the byte on the wire, shown when it ends:
	 * 16 SCK edges, up to 8 MOSI and 9 MISO changes */
	uint64_t edge_cycle[48];
	uint8_t edge_pin[48], edge_level[48];
	int nedges;

	spi_dev_t *dev[SPI_MAX_DEVICES];
	int ndev;

	spi_log_t log[SPI_LOG];		/* exchanges not yet fetched */
	unsigned log_head, log_len;
	uint64_t bytes;
	uint32_t activity;
} spi_t;

/* Take over the SPI registers at data addresses SPCR..SPDR, vector VECT. */
void spi_init(spi_t *s, avr_t *avr, uint16_t spcr, uint16_t spsr, uint16_t spdr,
	      uint8_t vect, trace_t *trace, spi_drive_t drive, void *param);

/* Put D on the bus; its chip select is the signal CS (a pin). */
int spi_attach(spi_t *s, spi_dev_t *d, signal_t *cs);

/* Cycles one byte takes with the current SPR/SPI2X. */
unsigned spi_byte_cycles(const spi_t *s);

/* Take the oldest logged exchange; 0 when none. */
int spi_log_pop(spi_t *s, spi_log_t *out);

#endif
