/* Unity settings for the firmware suites (included through
   UNITY_INCLUDE_CONFIG_H): 64-bit asserts, and on AVR output to UART0. */
#ifndef FSW_UNITY_CONFIG_H
#define FSW_UNITY_CONFIG_H

#define UNITY_SUPPORT_64

#if defined(__AVR__)
#ifdef __cplusplus
extern "C" {
#endif
void fsw_test_putc(int c);
#ifdef __cplusplus
}
#endif
#define UNITY_OUTPUT_CHAR(c) fsw_test_putc(c)
#define UNITY_EXCLUDE_FLOAT_PRINT
#else
#define UNITY_INCLUDE_DOUBLE
#define UNITY_USE_FLUSH_STDOUT
#endif

#endif
