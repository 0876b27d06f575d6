/*
 * unity_config.h - Unity's settings for the core's tests (read by unity.h
 * and unity.c with UNITY_INCLUDE_CONFIG_H): 64-bit integer assertions
 * (the tests compare Q values and counts as int64), and on the Cortex-M
 * images (SPVS_UNIT_TARGET) Unity's characters go out through
 * semihosting (target/unit_main.c), one line at a time.
 */
#ifndef SPVS_UNITY_CONFIG_H
#define SPVS_UNITY_CONFIG_H

#define UNITY_SUPPORT_64

#if defined(SPVS_UNIT_TARGET)
void unit_putc(int c);
void unit_flush(void);
#define UNITY_OUTPUT_CHAR(c) unit_putc(c)
#define UNITY_OUTPUT_FLUSH() unit_flush()
#endif

#endif /* SPVS_UNITY_CONFIG_H */
