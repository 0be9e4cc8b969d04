#include "drivers/adc_hw.h"

#include <avr/interrupt.h>
#include <avr/io.h>
#include <util/atomic.h>

#include "board.h"
#include "firmware/front.h"

/* F_CPU / 128 = 57.6 kHz ADC clock (datasheets: 50-200 kHz for 10 bits):
 * 13 ADC clocks = 1664 CPU cycles a conversion, all 8 channels in 1.81 ms
 * (docs/registers.md, "ADC": how fresh a reading is). At F_CPU / 64 the
 * interrupt came every 832 cycles and took ~9 % of the CPU, for readings
 * fresher than a control loop at 460800 baud can ask for them. */
#define ADC_PRESCALE (_BV(ADPS2) | _BV(ADPS1) | _BV(ADPS0))
#define ADC_START    (_BV(ADEN) | _BV(ADSC) | _BV(ADIE) | ADC_PRESCALE)

/* A channel's slot: its latest result and the ADMUX of the conversion after
 * it (the reference and the next enabled channel). Three bytes, as the
 * interrupt indexes them. */
typedef struct {
	volatile uint16_t value;
	uint8_t next;
} adc_slot_t;

_Static_assert(sizeof(adc_slot_t) == 3, "the interrupt's slot stride");

static struct {
	adc_slot_t slot[8];
	uint8_t refs;
} adc;

static void adc_start(uint8_t admux)
{
	ADMUX = admux;
	ADCSRA = ADC_START;
}

/* Its next conversion starts at its end: it cannot come again before then.
 * The channel is ADMUX's (written with it); ADLAR set marks the conversion
 * after a reference change, whose result is dropped (the reference
 * settles), and the same channel is converted again right-adjusted. In
 * assembly with three registers saved: the compiler's handler (r0, r1,
 * r18-r20, r24, r25, r30, r31, ~78 cycles) took ~9 % of the CPU at
 * F_CPU / 64. The M32-D's servo interrupt has a fixed budget for others
 * running before it: this one is short. */
ISR(ADC_vect, ISR_NAKED)
{
	__asm__ __volatile__(
		FRONT_ISR_LETS_RX_ASM
		"push r24\n\t"
		"in r24, __SREG__\n\t"
		"push r24\n\t"
		"push r30\n\t"
		"push r31\n\t"
		"in r30, %[admux]\n\t"
		"sbrc r30, %[adlar]\n\t"
		"rjmp 1f\n\t"
		"andi r30, 7\n\t"
		"mov r24, r30\n\t"
		"lsl r30\n\t"
		"add r30, r24\n\t"	/* 3 x the channel */
		"ldi r31, 0\n\t"
		"subi r30, lo8(-(%[slot]))\n\t"
		"sbci r31, hi8(-(%[slot]))\n\t"
		"in r24, %[adcl]\n\t"	/* ADCL first: it holds ADCH for us */
		"st Z, r24\n\t"
		"in r24, %[adch]\n\t"
		"std Z+1, r24\n\t"
		"ldd r30, Z+2\n"
		"1:\n\t"
		"andi r30, ~(1 << %[adlar])\n\t"
		"out %[admux], r30\n\t"
		"ldi r30, %[start]\n\t"
		"out %[adcsra], r30\n\t"
		"pop r31\n\t"
		"pop r30\n\t"
		"pop r24\n\t"
		"out __SREG__, r24\n\t"
		"pop r24\n\t"
		"reti\n"
		: : [admux] "I" (_SFR_IO_ADDR(ADMUX)), [adcl] "I" (_SFR_IO_ADDR(ADCL)),
		[adch] "I" (_SFR_IO_ADDR(ADCH)), [adcsra] "I" (_SFR_IO_ADDR(ADCSRA)),
		[adlar] "n" (ADLAR), [slot] "i" (adc.slot), [start] "n" (ADC_START));
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
			adc.slot[ch].value = 0;
		}
	}
	/* The reference needs a moment after a change: one conversion,
	 * dropped (ADLAR marks it). */
	uint8_t settle = (refs != adc.refs) ? _BV(ADLAR) : 0;
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
				adc.slot[ch].next = (uint8_t)(refs << REFS0 | next);
			}
			if (bits & 0x8000) {
				next = ch;
			}
		}
		ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
			adc_start(adc.slot[7].next | settle);
		}
	} else {
		ADMUX = 0;
	}
}

uint16_t adc_hw_value(uint8_t ch)
{
	uint16_t v;
	ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
		v = adc.slot[ch].value;
	}
	return v;
}
