//! The `ChassisDynamic` FMU: [`agrisim_chassis::ChassisDynamic`] behind the FMI 3.0 / 2.0 API.

agrisim_fmi::export_fmu!(agrisim_chassis::ChassisDynamic);
