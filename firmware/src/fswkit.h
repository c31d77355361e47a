// fswkit runtime: the one header generated code and sketches include.
#ifndef FSWKIT_H
#define FSWKIT_H

#include "fsw_config.h"
#include "fsw_version.h"
#include "fsw_types.h"
#include "fsw_app.h"
#include "fsw_f64.h"
#include "fsw_convert.h"
#include "fsw_element.h"
#include "fsw_pal.h"
#include "fsw_sv.h"
#include "fsw_window.h"
#include "fsw_machine.h"
#include "fsw_clock.h"
#include "fsw_executor.h"
#include "fsw_io.h"
#include "fsw_link.h"
#include "fsw_param.h"
#include "fsw_log.h"
#include "fsw_resume.h"
#include "fsw_parts.h"
#include "fsw_twi.h"
#include "fsw_sensor.h"
#include "fsw_baro.h"
#include "fsw_accel.h"
#include "fsw_vm.h"

#endif  // FSWKIT_H
