#ifndef LINUXCNC_STYLE_FK_H
#define LINUXCNC_STYLE_FK_H

#include "stewart.h"

/* context: a const stewart_geometry *. See stewart.h for the solver signature. */
int linuxcnc_style_fk(void *context, const double legs[6], double pose[6], int *iterations);

#endif
