//! The `ChassisKinematic` FMU: [`agrisim_chassis::ChassisKinematic`] behind the FMI 3.0 / 2.0 API.

agrisim_fmi::export_fmu!(agrisim_chassis::ChassisKinematic);
