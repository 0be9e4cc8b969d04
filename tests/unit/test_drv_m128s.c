/*
 * OR-AVR-M128-S: what only this board has. GPIO ports A and F (F = the ADC
 * port), 32 servo channels on CD4017 counters (no MCU pin per channel; the
 * counter clocks PE3-PE5, PB7 and reset PE6 are the servos' from reset),
 * SPI on B0-B3, UART0 on E0-E1, TWI on D0-D1, no motors.
 */
#include <stdio.h>
#include <string.h>

#include "drv_test.h"

enum { PA, PB, PC, PD, PE, PF, PG };

/* docs/registers.md, register map and introspection records. */
const board_t B = {
	.name = "m128s",
	.nregs = 0x0E,
	.ndrivers = 6,
	.intro = "00 00 01 00 00 02  00 21 01 01 02 04  00 01 01 01 06 02"
		 "  00 40 01 01 08 02  00 30 02 00 0A 02  00 02 01 00 0C 02",
	.gpio_nports = 2,
	.gpio_value = 0x02,
	.gpio_mode = 0x04,
	.gpio_port = { PA, PF },
	.spi_data = 0x06,
	.spi_config = 0x07,
	.adc_rc = 0x08,
	.adc_rd = 0x09,
	.adc_port = PF,
	.adc_gpio = 1,
	.servo_rs = 0x0A,
	.servo_sp = 0x0B,
	.servo_channels = 32,
};

#define VAL_A 0x02
#define VAL_F 0x03
#define MODE_A 0x04
#define MODE_F 0x05
#define SPI_CFG 0x07
#define ADC_RC 0x08
#define RS 0x0A
#define SP 0x0B

/* Ports no GPIO register may reach: B, C, D, E, G. */
static void other_ports(uint8_t out[BOARD_NPORTS], uint8_t ddr[BOARD_NPORTS])
{
	memcpy(out, port_out, BOARD_NPORTS);
	memcpy(ddr, port_ddr, BOARD_NPORTS);
	out[PA] = out[PF] = ddr[PA] = ddr[PF] = 0;
}

static void test_gpio(void)
{
	uint8_t out0[BOARD_NPORTS], ddr0[BOARD_NPORTS], out1[BOARD_NPORTS], ddr1[BOARD_NPORTS];

	boot();
	/* The manual's example: F3 to R+3 (mode register of port F) makes
	 * lines 2 and 3 of port F inputs, the others outputs. */
	WRITE(MODE_F, "F3", REG_OK);
	CHECK_EQ(port_ddr[PF], 0xF3);
	CHECK_EQ(port_ddr[PA], 0x00);
	READ(MODE_F, 1, "F3");
	READ(MODE_A, 1, "00");

	/* Register order: values A, F; modes A, F. */
	other_ports(out0, ddr0);
	WRITE(VAL_A, "A5", REG_OK);
	WRITE(VAL_F, "5A", REG_OK);
	WRITE(MODE_A, "3C", REG_OK);
	CHECK_EQ(port_out[PA], 0xA5);
	CHECK_EQ(port_out[PF], 0x5A);
	CHECK_EQ(port_ddr[PA], 0x3C);
	CHECK_EQ(port_ddr[PF], 0xF3);
	port_ext[PA] = 0x0F;
	port_ext[PF] = 0xFF;
	READ(VAL_A, 1, "27");   /* (A5 & 3C) | (0F & C3) */
	READ(VAL_F, 1, "5E");   /* (5A & F3) | (FF & 0C) */
	/* Masks and all eight lines of each port. */
	WRITE(VAL_F, "FF 0C", REG_OK);
	CHECK_EQ(port_out[PF], 0x5E);
	WRITE(MODE_A, "FF FF", REG_OK);
	WRITE(MODE_F, "FF", REG_OK);
	WRITE(VAL_A, "FF", REG_OK);
	WRITE(VAL_F, "FF", REG_OK);
	CHECK_EQ(port_ddr[PA], 0xFF);
	CHECK_EQ(port_ddr[PF], 0xFF);
	CHECK_EQ(port_out[PA], 0xFF);
	CHECK_EQ(port_out[PF], 0xFF);
	other_ports(out1, ddr1);
	CHECK(memcmp(out0, out1, sizeof out0) == 0 && memcmp(ddr0, ddr1, sizeof ddr0) == 0);

	/* ADC lines of port F and chip selects on A or F leave GPIO. */
	WRITE(ADC_RC, "01 81", REG_OK);
	CHECK_EQ(port_ddr[PF], 0x7E);
	CHECK_EQ(port_out[PF], 0x7E);
	WRITE(SPI_CFG, "00 00 04", REG_OK);
	WRITE(SPI_CFG, "01 01 03", REG_OK);
	READ(SPI_CFG, 9, "02 00 04 01 03 FF FF FF FF");
	CHECK_EQ(pins_owner(PIN(PA, 4)), PIN_SPI_CS);
	CHECK_EQ(pins_owner(PIN(PF, 3)), PIN_SPI_CS);
	WRITE(MODE_A, "00", REG_OK);
	WRITE(VAL_A, "00", REG_OK);
	WRITE(MODE_F, "00", REG_OK);
	WRITE(VAL_F, "00", REG_OK);
	CHECK_EQ(port_ddr[PA], 0x10);
	CHECK_EQ(port_out[PA], 0x10);
	CHECK_EQ(port_ddr[PF], 0x08);
	CHECK_EQ(port_out[PF], 0x08);
	CHECK_EQ(pins_gpio_mask(PA), 0xEF);
	CHECK_EQ(pins_gpio_mask(PF), 0x76);
	other_ports(out1, ddr1);
	CHECK(memcmp(out0, out1, sizeof out0) == 0 && memcmp(ddr0, ddr1, sizeof ddr0) == 0);
}

static void test_fixed_pins(void)
{
	boot();
	CHECK_EQ(pins_owner(PIN(PD, 2)), PIN_UART);  /* USART1 */
	CHECK_EQ(pins_owner(PIN(PD, 3)), PIN_UART);
	CHECK_EQ(pins_owner(PIN(PE, 0)), 0);  /* ISP pins: no function */
	CHECK_EQ(pins_owner(PIN(PE, 1)), 0);
	CHECK_EQ(pins_owner(PIN(PD, 0)), PIN_TWI);
	CHECK_EQ(pins_owner(PIN(PD, 1)), PIN_TWI);
	for (unsigned l = 0; l < 4; l++) {
		CHECK_EQ(pins_owner(PIN(PB, l)), PIN_SPI);
	}
	CHECK_EQ(pins_owner(PIN(PE, 3)), PIN_SERVO_CLK);
	CHECK_EQ(pins_owner(PIN(PE, 4)), PIN_SERVO_CLK);
	CHECK_EQ(pins_owner(PIN(PE, 5)), PIN_SERVO_CLK);
	CHECK_EQ(pins_owner(PIN(PB, 7)), PIN_SERVO_CLK);
	CHECK_EQ(pins_owner(PIN(PE, 6)), PIN_SERVO_CLK);
	/* GPIO has all of A and F at reset. */
	CHECK_EQ(pins_gpio_mask(PA), 0xFF);
	CHECK_EQ(pins_gpio_mask(PF), 0xFF);
	/* No motor driver: sys follows the servos at 0C-0D, the map ends there. */
	CHECK(regmap_select(0x0B));
	CHECK(regmap_select(0x0D));
	CHECK(!regmap_select(0x0E));
}

static void test_servos(void)
{
	char t[400], want[300];

	boot();
	uint8_t pa = port_out[PA], pf = port_out[PF], da = port_ddr[PA], df = port_ddr[PF];
	/* 32 channels in two writes of 16 triples: width 600 + 50n. */
	for (unsigned half = 0; half < 2; half++) {
		t[0] = 0;
		for (unsigned i = 16 * half; i < 16 * half + 16; i++) {
			unsigned w = 600 + 50 * i;
			sprintf(t + strlen(t), "%02X %02X %02X ", i, w >> 8, w & 0xFF);
		}
		WRITE(SP, t, REG_OK);
	}
	CHECK_EQ(hw.servo_applies, 2);
	for (unsigned i = 0; i < 32; i++) {
		CHECK_EQ(hw.servo_width[i], 600 + 50 * i);
	}
	/* Counters need no pin per channel: GPIO keeps all of A and F. */
	CHECK_EQ(pins_gpio_mask(PA), 0xFF);
	CHECK_EQ(pins_gpio_mask(PF), 0xFF);
	CHECK_EQ(port_out[PA], pa);
	CHECK_EQ(port_out[PF], pf);
	CHECK_EQ(port_ddr[PA], da);
	CHECK_EQ(port_ddr[PF], df);
	READ(RS, 4, "FF FF FF FF");
	/* All 32 widths in one 64-byte read. */
	want[0] = 0;
	for (unsigned i = 0; i < 32; i++) {
		unsigned w = 600 + 50 * i;
		sprintf(want + strlen(want), "%s%02X %02X", i ? " " : "", w >> 8, w & 0xFF);
	}
	READ(SP, 64, want);
	/* From channel 16 on (the second half of the gateway's two reads). */
	WRITE(SP, "10", REG_OK);
	READ(SP, 32, want + 16 * 6);
	WRITE(SP, "1F", REG_OK);
	READ(SP, 2, "08 66");          /* 600 + 50 * 31 = 2150 */
	/* Channel 31 exists, 32 does not. */
	WRITE(SP, "1F 00 00", REG_OK);
	READ(RS, 4, "7F FF FF FF");
	READ(RS, 2, "7F FF");
	REFUSED(SP, REG_BAD_VALUE, "20 05 DC", "00 05 DC 20 05 DC", "20");
	/* Counter boundaries: channels 7 | 8, 23 | 24 are separate bits. */
	WRITE(SP, "08 00 00 17 00 00", REG_OK);
	READ(RS, 4, "7F 7F FE FF");
}

static void test_adc_spi_port_f(void)
{
	boot();
	/* A chip select on F2 refuses ADC channel 2; F0 (a GPIO output driven
	 * high) must stay so. */
	WRITE(MODE_F, "01", REG_OK);
	WRITE(VAL_F, "01", REG_OK);
	WRITE(SPI_CFG, "00 01 02", REG_OK);
	REFUSED(ADC_RC, REG_PIN_BUSY, "00 05");
	CHECK_EQ(port_ddr[PF], 0x05);
	CHECK_EQ(port_out[PF], 0x05);
	/* An ADC line refuses a chip select. */
	WRITE(ADC_RC, "00 20", REG_OK);
	REFUSED(SPI_CFG, REG_PIN_BUSY, "01 01 05", "00 01 05" /* also as a rebinding */);
	READ(SPI_CFG, 9, "02 01 02 FF FF FF FF FF FF");
	/* Port numbers are the GPIO driver's: 1 is F, 2 does not exist. */
	WRITE(SPI_CFG, "01 02 00", REG_BAD_VALUE);
	/* Exchanges on an F line. */
	static const uint8_t miso[] = { 0x00, 0x12 };
	spi_script(miso, 2);
	hw_log_clear();
	WRITE(0x06, "00 03 00", REG_OK);
	CHECK_EQ(strcmp(hw_log, "WF04:00 X0300>0012 WF04:04 "), 0);
	READ(0x06, 2, "00 12");
}

void board_tests(void)
{
	test_gpio();
	test_fixed_pins();
	test_servos();
	test_adc_spi_port_f();
}
