//! Reads an event file to its end and prints the count and the time: `cargo run --release
//! -p eenf-events --example decode_count -- FILE` (for profiling a reader).

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args_os()
        .nth(1)
        .ok_or("usage: decode_count FILE")?;
    let t0 = std::time::Instant::now();
    let mut r = eenf_events::open(std::path::Path::new(&path))?;
    let mut n = 0u64;
    while let Some(b) = r.next_batch()? {
        n += b.len() as u64;
    }
    let dt = t0.elapsed().as_secs_f64();
    println!(
        "{n} events in {dt:.3} s = {:.1} M events/s",
        n as f64 / dt / 1e6
    );
    Ok(())
}
