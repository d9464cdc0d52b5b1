//! `scatterloc mtl locate`: Algorithm 1 (§4) on a network file and a ranges file, through the
//! library's [`scatterloc::mtl::input::locate_request`].

use super::*;

/// `scatterloc mtl locate`.
pub fn mtl_locate(args: &MtlLocateArgs) -> Result<(), CliError> {
    let net_path = args.network.as_str();
    let ranges_path = args.ranges.as_str();
    one_stdin(&[
        ("network", Some(net_path)),
        ("ranges", Some(ranges_path)),
        ("table", args.table.as_deref()),
    ])?;
    let spec = model_spec(args)?;
    let cfg = mtl_config(args);
    let out_path = match args.out.as_deref() {
        Some(p) => {
            Format::of("out", p, &[Format::Json])?;
            check_writable("out", p)?;
            Some(p)
        }
        None => None,
    };
    let network: NetworkInput = read_file("network", net_path)?;
    let ranges: RangesInput = read_file("ranges", ranges_path)?;
    let req = LocateRequest {
        network,
        ranges,
        model: spec,
    };
    let doc = locate_request(&req, &cfg).map_err(|(stage, e)| match stage {
        LocateStage::Network => CliError::usage(format!("--network {net_path}: {e}")),
        LocateStage::Ranges => CliError::usage(format!("--ranges {ranges_path}: {e}")),
        LocateStage::Model => core_error(&e, "--model"),
        LocateStage::Algorithm => core_error(&e, &format!("--ranges {ranges_path}")),
    })?;
    match out_path {
        None => emit(
            &serde_json::to_string(&doc)
                .map_err(|e| CliError::output(format!("encoding JSON: {e}")))?,
        ),
        Some(p) => {
            write_json_file("out", p, &doc)?;
            emit_summary(&format!(
                "{{\"count\":{},\"out\":{}}}",
                doc.count,
                serde_json::to_string(p).unwrap_or_default()
            ))
        }
    }
}
