//! A zip archive of finished recordings for the teacher's download: stored entries (an MCAP
//! file is already compressed chunk by chunk), CRC-32 checked, in the classic (not Zip64)
//! format, so each file and the archive must stay under 4 GiB.

/// Why an archive was not written.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ZipError {
    /// A file or the archive over the classic format's 4 GiB, or more than 65535 files.
    #[error(
        "the recordings are too large for one zip archive (4 GiB, 65535 files): download them one by one"
    )]
    TooLarge,
}

/// A zip archive of `files` (name in the archive, bytes).
pub fn zip_stored(files: &[(String, Vec<u8>)]) -> Result<Vec<u8>, ZipError> {
    if files.len() > 0xFFFF {
        return Err(ZipError::TooLarge);
    }
    let u32_of = |n: usize| u32::try_from(n).map_err(|_| ZipError::TooLarge);
    let mut out = Vec::new();
    let mut central = Vec::new();
    for (name, data) in files {
        let offset = u32_of(out.len())?;
        let size = u32_of(data.len())?;
        let crc = crc32fast::hash(data);
        let n = name.as_bytes();
        let nlen = u16::try_from(n.len()).map_err(|_| ZipError::TooLarge)?;
        // Local file header: version 2.0, UTF-8 names (bit 11), stored, no time.
        out.extend_from_slice(&0x0403_4b50u32.to_le_bytes());
        out.extend_from_slice(&20u16.to_le_bytes());
        out.extend_from_slice(&0x0800u16.to_le_bytes());
        out.extend_from_slice(&0u16.to_le_bytes());
        out.extend_from_slice(&0u16.to_le_bytes());
        out.extend_from_slice(&0x21u16.to_le_bytes()); // 1980-01-01
        out.extend_from_slice(&crc.to_le_bytes());
        out.extend_from_slice(&size.to_le_bytes());
        out.extend_from_slice(&size.to_le_bytes());
        out.extend_from_slice(&nlen.to_le_bytes());
        out.extend_from_slice(&0u16.to_le_bytes());
        out.extend_from_slice(n);
        out.extend_from_slice(data);
        // Central directory entry.
        central.extend_from_slice(&0x0201_4b50u32.to_le_bytes());
        central.extend_from_slice(&20u16.to_le_bytes());
        central.extend_from_slice(&20u16.to_le_bytes());
        central.extend_from_slice(&0x0800u16.to_le_bytes());
        central.extend_from_slice(&0u16.to_le_bytes());
        central.extend_from_slice(&0u16.to_le_bytes());
        central.extend_from_slice(&0x21u16.to_le_bytes());
        central.extend_from_slice(&crc.to_le_bytes());
        central.extend_from_slice(&size.to_le_bytes());
        central.extend_from_slice(&size.to_le_bytes());
        central.extend_from_slice(&nlen.to_le_bytes());
        central.extend_from_slice(&[0u8; 12]); // extra, comment, disk, attributes
        central.extend_from_slice(&offset.to_le_bytes());
        central.extend_from_slice(n);
    }
    let cd_offset = u32_of(out.len())?;
    let cd_size = u32_of(central.len())?;
    out.extend_from_slice(&central);
    let count = files.len() as u16;
    out.extend_from_slice(&0x0605_4b50u32.to_le_bytes());
    out.extend_from_slice(&[0u8; 4]);
    out.extend_from_slice(&count.to_le_bytes());
    out.extend_from_slice(&count.to_le_bytes());
    out.extend_from_slice(&cd_size.to_le_bytes());
    out.extend_from_slice(&cd_offset.to_le_bytes());
    out.extend_from_slice(&0u16.to_le_bytes());
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn python_and_unzip_read_the_archive_back() {
        let files = vec![
            ("Ada-1.mcap".to_string(), b"first file".to_vec()),
            ("Zoë-2.mcap".to_string(), vec![0u8, 1, 2, 255]),
            ("empty.mcap".to_string(), Vec::new()),
        ];
        let z = zip_stored(&files).unwrap();
        let dir = std::env::current_exe()
            .unwrap()
            .with_file_name("test-tmp")
            .join(format!("nh-zip-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("class.zip");
        std::fs::write(&p, &z).unwrap();
        // Python's zipfile checks the headers, the central directory and every CRC.
        let script = "import sys, zipfile\nz = zipfile.ZipFile(sys.argv[1])\nassert z.testzip() is None\nfor i in z.infolist(): print(i.filename, z.read(i).hex())";
        let out = std::process::Command::new("python3")
            .args(["-c", script])
            .arg(&p)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert_eq!(
            String::from_utf8(out.stdout).unwrap(),
            format!(
                "Ada-1.mcap {}\nZoë-2.mcap 000102ff\nempty.mcap \n",
                "first file"
                    .bytes()
                    .map(|b| format!("{b:02x}"))
                    .collect::<String>()
            )
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
