/*
 * i2c_phy.h: the bit-level front every I2C device shares (the parts, a
 * board's TWI in slave mode). It watches the lines as the bus tells their
 * edges: START, repeated START and STOP from SDA changing while SCL is
 * high, at any point; the address and data bits shifted in at SCL's rising
 * edges; its acknowledge and the bits it sends driven on SDA at SCL's
 * falling edges; SCL held low while its device asks (clock stretching).
 * It calls the device's byte-level ops (twi_dev_ops_t) at the edges
 * twi_bus.h names. Once it did not acknowledge an address, or its transfer
 * ended, it sees nothing but START and STOP (the bus does not tell it the
 * other edges), which keeps a busy bus cheap.
 */
#ifndef SIM_I2C_PHY_H
#define SIM_I2C_PHY_H

#include "periph/twi_bus.h"

/* SDA changed while SCL was high: a START (START 1) or a STOP. */
void i2c_phy_condition(twi_bus_t *bus, twi_dev_t *d, int start);

/* SCL (SCL_LINE 1) or SDA changed level (the bus's levels are the new
 * ones); SDA changes here only while SCL is low. */
void i2c_phy_edge(twi_bus_t *bus, twi_dev_t *d, int scl_line);

/* D's device let SCL go at CYCLE (twi_bus_release): a byte it sends begins. */
void i2c_phy_released(twi_bus_t *bus, twi_dev_t *d, uint64_t cycle);

/* The master begins clocking the byte D waits to send (twi_bus_byte):
 * its first bit goes on SDA at CYCLE. */
void i2c_phy_load(twi_bus_t *bus, twi_dev_t *d, uint64_t cycle);

/* D's front goes to STATE, the bus's count of active fronts (nactive)
 * kept with it. */
void i2c_phy_state(twi_bus_t *bus, twi_dev_t *d, twi_phy_state_t state);

#endif
