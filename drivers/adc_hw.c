#include "drivers/adc_hw.h"

#include <avr/interrupt.h>
#include <avr/io.h>
#include <util/atomic.h>

#include "board.h"
#include "firmware/front.h"

/* F_CPU / 64 = 115.2 kHz ADC clock (datasheet: 50-200 kHz for 10 bits):
 * 13 ADC clocks = 832 CPU cycles a conversion, all 8 channels in < 1 ms. */
#define ADC_PRESCALE (_BV(ADPS2) | _BV(ADPS1))

static struct {
	volatile uint16_t value[8];
	uint8_t refs;
	uint8_t ch;        /* channel being converted */
	uint8_t next[8];   /* the enabled channel after channel n */
	uint8_t discard;   /* conversions to drop after a reference change */
} adc;

static void adc_start(uint8_t ch)
{
	adc.ch = ch;
	ADMUX = (uint8_t)(adc.refs << REFS0 | ch);
	ADCSRA = _BV(ADEN) | _BV(ADSC) | _BV(ADIE) | ADC_PRESCALE;
}

/* Its next conversion starts at its end: it cannot come again before then. */
ISR(ADC_vect, FRONT_ISR_LETS_RX)
{
	uint8_t lo = ADCL;
	uint8_t hi = ADCH;
	if (adc.discard) {
		adc.discard--;
	} else {
		adc.value[adc.ch] = (uint16_t)(hi << 8 | lo);
	}
	/* Looked up, not searched: this interrupt must stay short, the M32-D
	 * servo interrupt has a fixed budget for others running before it. */
	adc_start(adc.next[adc.ch]);
}

void adc_hw_config(uint8_t refs, uint8_t mask)
{
	ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
		ADCSRA = 0;  /* stop; a conversion under way is dropped */
	}
	/* (masks walked a bit at a time: a shift by a channel's number is a
	 * loop on the AVR) */
	uint8_t off = (uint8_t)~mask;
	for (uint8_t ch = 0; off; ch++, off >>= 1) {
		if (off & 1) {
			adc.value[ch] = 0;
		}
	}
	/* The reference needs a moment after a change: one conversion. */
	adc.discard = (refs != adc.refs) ? 1 : 0;
	adc.refs = refs;
	if (mask) {
		/* Each channel's enabled one after it, round the 8: the channels
		 * walked down twice round (the mask's bits from the top), the
		 * last enabled one seen is the next one up (itself when alone). */
		uint16_t bits = (uint16_t)(mask << 8 | mask);
		uint8_t next = 0;
		for (uint8_t i = 16; i--; bits <<= 1) {
			uint8_t ch = i & 7;
			if (i < 8) {
				adc.next[ch] = next;
			}
			if (bits & 0x8000) {
				next = ch;
			}
		}
		ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
			adc_start(adc.next[7]);
		}
	} else {
		ADMUX = 0;
	}
}

uint16_t adc_hw_value(uint8_t ch)
{
	uint16_t v;
	ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
		v = adc.value[ch];
	}
	return v;
}
