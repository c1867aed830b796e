/* studyapp device protocol v2: the loop on the device (docs/device-protocol.md, "Version 2").
 *
 * A device whose INFO has the loop section with loop = 1 runs studyapp's loop (studyapp_loop.h) itself:
 *
 *     sd_init(&dev, info, len, alpha);        INFO of protocol_version 2, loop = 1, its estimator kinds
 *     sd_attach_loop(&dev, &loop);            the sl_loop over the firmware's arrays (same kinds, same order)
 *     per sample, as in version 1:
 *     sd_rx(&dev, bytes, n);                  CONTROL (queued, 16 deep) and ALIVE (the keep-alive) among them
 *     sd_sample(&dev, raw);                   the CONTROLs due, then the loop on this sample's sensors
 *     f = sd_actuate(&dev);                   the safety core (arm, ramp, keep-alive watchdog, clamps) on the
 *                                             loop's force; a TELEMETRY frame every START.packet samples
 *     n = sd_tx(&dev, out, cap);
 *
 * The loop's sensors: x, a, v from the first channel of each kind (position, acceleration, velocity), in SI
 * (gain x count + offset for a counts channel, as sent); a device without an acceleration (or velocity)
 * channel gives 0 there. The loop steps only on streamed samples. Before the first CONTROL since START the
 * setting is the bow lifted, gain 0, force scale 1 and the velocity sensor as the source (control id 0).
 *
 * A non-finite value latches the loop's own fault (studyapp_loop.h: force 0 for good); the device then sends
 * FAULT INTERNAL once, its detail the loop's fault code (1 sensor, 2 estimate, 3 string, 4 force).
 */
#ifndef STUDYAPP_DEVICE_LOOP_H
#define STUDYAPP_DEVICE_LOOP_H

#include "studyapp_device.h"
#include "studyapp_loop.h"

/* 0 on success; -1 if the INFO has no device loop, L's estimators are not INFO's, or sl_check(L) fails.
 * Until a loop is attached, a device loop counts CONTROL and ALIVE as corrupt and applies 0 N. */
int sd_attach_loop(sd_device *d, sl_loop *L);

/* control id in effect, CONTROLs queued, ALIVE's seen, the loop's fault code */
void sd_loop_counters(const sd_device *d, uint32_t out[4]);

#endif
