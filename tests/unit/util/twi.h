/*
 * Host stand-in for avr-libc's <util/twi.h>: the TWI status codes of the
 * ATmega32/128 datasheets (TWSR bits 7..3), under avr-libc's names, so that
 * i2c_slave/slave_fsm.c compiles for the unit tests unchanged.
 */
#ifndef UNIT_UTIL_TWI_H
#define UNIT_UTIL_TWI_H

#define TW_BUS_ERROR            0x00
#define TW_ST_SLA_ACK           0xA8
#define TW_ST_ARB_LOST_SLA_ACK  0xB0
#define TW_ST_DATA_ACK          0xB8
#define TW_ST_DATA_NACK         0xC0
#define TW_ST_LAST_DATA         0xC8
#define TW_SR_SLA_ACK           0x60
#define TW_SR_ARB_LOST_SLA_ACK  0x68
#define TW_SR_GCALL_ACK         0x70
#define TW_SR_DATA_ACK          0x80
#define TW_SR_DATA_NACK         0x88
#define TW_SR_STOP              0xA0
#define TW_NO_INFO              0xF8

#endif
